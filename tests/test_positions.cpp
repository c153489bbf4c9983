// Positions in the caller's layout (PositionsView: float32 or float64, any strides) through every
// entry point that takes them, on the host and in the backend's memory: the same pairs and contacts
// as contiguous float32, and one-line errors for views that cannot be right.

#include "test_support.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#if defined(KDET_HAS_CUDA)
#include <cuda_runtime.h>
#endif

namespace kdet {
namespace {

/// A mesh's positions laid out with the given strides (in elements) in a buffer of their own whose
/// other elements are NaN, so that a read of a wrong element shows as a rejected coordinate.
struct Laid {
    std::vector<float> floats;
    std::vector<double> doubles;
    std::ptrdiff_t origin = 0; ///< the element vertex 0's x lies at
    PositionsView view;

    const void* buffer() const { return view.is_double ? static_cast<const void*>(doubles.data()) : floats.data(); }
    std::size_t bytes() const { return view.is_double ? doubles.size() * sizeof(double) : floats.size() * sizeof(float); }
    /// The view of the same layout in a copy of buffer() at `copy`.
    PositionsView at(void* copy) const {
        PositionsView v = view;
        const std::size_t item = view.is_double ? sizeof(double) : sizeof(float);
        v.data = static_cast<const unsigned char*>(copy) + static_cast<std::size_t>(origin) * item;
        return v;
    }
};

struct Layout {
    const char* name;
    bool is_double;
    std::ptrdiff_t row_stride, column_stride; ///< 0 for column_stride: the vertex count (Fortran order)
};

const Layout layouts[] = {
    {"float32 C order", false, 3, 1},          {"float64 C order", true, 3, 1},
    {"float64 Fortran order", true, 1, 0},     {"float32 Fortran order", false, 1, 0},
    {"float32 every other row", false, 6, 1},  {"float32 columns 1-3 of 5", false, 5, 1},
    {"float64 rows reversed", true, -3, 1},    {"float32 columns reversed", false, 3, -1},
    {"float64 every third row reversed", true, -9, 1},
};

Laid lay_out(const TetMesh& mesh, const Layout& layout) {
    const auto n = static_cast<std::ptrdiff_t>(mesh.num_vertices());
    const std::ptrdiff_t rs = layout.row_stride, cs = layout.column_stride ? layout.column_stride : n;
    const std::ptrdiff_t lo = std::min<std::ptrdiff_t>(0, (n - 1) * rs) + std::min<std::ptrdiff_t>(0, 2 * cs);
    const std::ptrdiff_t hi = std::max<std::ptrdiff_t>(0, (n - 1) * rs) + std::max<std::ptrdiff_t>(0, 2 * cs);
    // A column slice leaves room for the columns after it, as its parent array has.
    const auto size = static_cast<std::size_t>(hi - lo + 1 + (rs == 5 ? 2 : 0));
    Laid laid;
    laid.origin = -lo;
    if (layout.is_double)
        laid.doubles.assign(size, std::numeric_limits<double>::quiet_NaN());
    else
        laid.floats.assign(size, std::numeric_limits<float>::quiet_NaN());
    for (std::ptrdiff_t v = 0; v < n; ++v)
        for (std::ptrdiff_t k = 0; k < 3; ++k) {
            const auto at = static_cast<std::size_t>(laid.origin + v * rs + k * cs);
            const double value = mesh.positions[static_cast<std::size_t>(3 * v + k)];
            if (layout.is_double)
                laid.doubles[at] = value;
            else
                laid.floats[at] = static_cast<float>(value);
        }
    laid.view = PositionsView{nullptr, layout.is_double, mesh.num_vertices(), rs, cs};
    laid.view = laid.at(const_cast<void*>(laid.buffer()));
    return laid;
}

/// Pairs and contacts of a frame, with the answer they must equal.
void expect_same_frame(const FrameResult& got, const FrameResult& expected, const std::string& where) {
    EXPECT_EQ(got.pairs, expected.pairs) << where;
    EXPECT_EQ(got.colliding, expected.colliding) << where;
    ASSERT_EQ(got.contacts.size(), expected.contacts.size()) << where;
    for (std::size_t k = 0; k < got.contacts.size(); ++k)
        ASSERT_EQ(std::memcmp(&got.contacts[k], &expected.contacts[k], sizeof(Contact)), 0) << where << ", pair " << k;
}

/// `call` throws a kdet::Error whose one-line message holds `naming`.
void expect_error_naming(const std::function<void()>& call, const std::string& naming) {
    const std::string message = test::error_message(call);
    EXPECT_NE(message.find(naming), std::string::npos) << message;
}

class Positions : public ::testing::Test {
protected:
    void SetUp() override {
        options_.contacts = true;
        a_ = test::random_soup(1500, 4.0, 2.0, 211);
        b_ = test::random_soup(1500, 4.0, 2.0, 212);
        moved_ = test::moved(b_, 0.3, -0.2, 0.1, 0.0);
        Detector reference(options_);
        reference.set_self_collision(reference.add_object(a_), true);
        const ObjectId ib = reference.add_object(b_);
        const std::vector<float> xyz(moved_.positions.begin(), moved_.positions.end());
        reference.set_positions(ib, xyz.data(), moved_.num_vertices());
        expected_ = reference.detect();
        ASSERT_GT(expected_.pairs.size(), 20u);
    }
    /// A detector with a_ (self-colliding) and b_ at rest, its first frame run.
    Detector detector_at_rest() const {
        Detector detector(options_);
        detector.set_self_collision(detector.add_object(a_), true);
        detector.add_object(b_);
        detector.detect();
        return detector;
    }

    DetectorOptions options_;
    TetMesh a_, b_, moved_;
    FrameResult expected_;
};

TEST_F(Positions, EveryLayoutGivesThePairsOfContiguousFloatThroughEveryEntryPoint) {
    for (const Layout& layout : layouts) {
        const Laid laid = lay_out(moved_, layout);
        Detector host = detector_at_rest();
        host.set_positions(1, laid.view);
        expect_same_frame(host.detect(), expected_, std::string("set_positions, ") + layout.name);

        Detector device = detector_at_rest();
        device.set_positions_on_device(1, laid.view);
        expect_same_frame(device.detect(), expected_, std::string("set_positions_on_device, ") + layout.name);

        // The rest shape in that layout: the moved mesh added as it is.
        Detector added(options_);
        added.set_self_collision(added.add_object(a_), true);
        added.add_object(laid.view, moved_.tets.data(), moved_.num_tets());
        expect_same_frame(added.detect(), expected_, std::string("add_object, ") + layout.name);
    }
}

TEST_F(Positions, ViewsThatCannotBeRightAreOneLineErrors) {
    Detector detector = detector_at_rest();
    const Laid laid = lay_out(moved_, layouts[2]);
    const std::size_t n = b_.num_vertices();
    PositionsView null_data = laid.view;
    null_data.data = nullptr;
    PositionsView too_few = laid.view;
    too_few.vertex_count = n - 1;
    PositionsView overflowing = laid.view;
    overflowing.row_stride = std::numeric_limits<std::ptrdiff_t>::max() / 4;
    PositionsView overflowing_backwards = laid.view;
    overflowing_backwards.column_stride = std::numeric_limits<std::ptrdiff_t>::min();
    const std::string count = "object 1: got " + std::to_string(n - 1) + " vertices, expected " + std::to_string(n);
    for (const bool on_device : {false, true}) {
        const auto set = [&](const PositionsView& view) {
            return [&detector, &view, on_device] {
                if (on_device)
                    detector.set_positions_on_device(1, view);
                else
                    detector.set_positions(1, view);
            };
        };
        expect_error_naming(set(null_data), "object 1: the positions' data pointer is null");
        expect_error_naming(set(too_few), count);
        expect_error_naming(set(overflowing), "object 1: the positions' strides (" +
                                                  std::to_string(overflowing.row_stride) + ", " +
                                                  std::to_string(overflowing.column_stride) + " elements) reach beyond");
        expect_error_naming(set(overflowing_backwards), "object 1: the positions' strides");
    }
    expect_error_naming([&] { detector.add_object(null_data, moved_.tets.data(), moved_.num_tets()); },
                        "object 2: the positions' data pointer is null");
    expect_error_naming([&] { detector.add_object(overflowing, moved_.tets.data(), moved_.num_tets()); },
                        "object 2: the positions' strides");
    EXPECT_EQ(detector.object_count(), 2u);
    // An empty object needs no data.
    EXPECT_EQ(detector.add_object(PositionsView{}, nullptr, 0), 2u);
    // Nothing was taken from the rejected calls: the detector still sees the rest shape.
    Detector at_rest = detector_at_rest();
    EXPECT_EQ(detector.detect().pairs, at_rest.detect().pairs);
}

TEST_F(Positions, NonFiniteCoordinatesInAnyLayoutAreRejectedByVertex) {
    Detector detector = detector_at_rest();
    const std::vector<TetPair> before = detector.detect().pairs;
    Laid laid = lay_out(moved_, layouts[2]); // float64, Fortran order: y of vertex 7 is element n + 7
    laid.doubles[b_.num_vertices() + 7] = 1e300; // finite as a double, not as the float32 stored
    expect_error_naming([&] { detector.set_positions(1, laid.view); }, "object 1: vertex 7 has a non-finite coordinate");
    detector.set_positions_on_device(1, laid.view);
    expect_error_naming([&] { detector.detect(); }, "object 1: vertex 7 of the positions given on the device");
    EXPECT_EQ(detector.detect().pairs, before);
}

#if defined(KDET_HAS_CUDA)
/// Positions in device memory in every layout, on the caller's stream: gathered on the device, with
/// the CPU's pairs, flags and contacts.
TEST_F(Positions, EveryLayoutInDeviceMemoryGivesTheCpusPairsOnTheCallersStream) {
    std::string reason;
    if (!cuda_available(&reason)) GTEST_SKIP() << "CUDA backend not tested: " << reason;
    cudaStream_t stream = nullptr;
    ASSERT_EQ(cudaStreamCreateWithFlags(&stream, cudaStreamNonBlocking), cudaSuccess);
    options_.backend = Backend::cuda;
    options_.cuda_stream = stream;
    for (const Layout& layout : layouts) {
        const Laid laid = lay_out(moved_, layout);
        void* device = nullptr;
        ASSERT_EQ(cudaMalloc(&device, laid.bytes()), cudaSuccess);
        ASSERT_EQ(cudaMemcpyAsync(device, laid.buffer(), laid.bytes(), cudaMemcpyHostToDevice, stream), cudaSuccess);
        Detector detector = detector_at_rest();
        detector.set_positions_on_device(1, laid.at(device));
        expect_same_frame(detector.detect(), expected_, std::string("device memory, ") + layout.name);
        // The detector's copy was made on its stream before the frame: the caller's memory may go.
        cudaFree(device);
        expect_same_frame(detector.detect(), expected_, std::string("device memory freed, ") + layout.name);
    }

    Laid bad = lay_out(moved_, layouts[6]); // float64, rows reversed
    bad.doubles[static_cast<std::size_t>(bad.origin - 3 * 11 + 2)] = std::numeric_limits<double>::infinity(); // z of vertex 11
    void* device = nullptr;
    ASSERT_EQ(cudaMalloc(&device, bad.bytes()), cudaSuccess);
    ASSERT_EQ(cudaMemcpy(device, bad.buffer(), bad.bytes(), cudaMemcpyHostToDevice), cudaSuccess);
    Detector detector = detector_at_rest();
    const std::vector<TetPair> before = detector.detect().pairs;
    detector.set_positions_on_device(1, bad.at(device));
    expect_error_naming([&] { detector.detect(); }, "object 1: vertex 11 of the positions given on the device");
    EXPECT_EQ(detector.detect().pairs, before);
    cudaFree(device);
    cudaStreamDestroy(stream);
}
#endif

} // namespace
} // namespace kdet
