#pragma once
/// @file detector.hpp
/// @brief Finding colliding tetrahedra: a Detector for frame-by-frame use, collide() for one-off use.

#include <kdet/mesh.hpp>
#include <kdet/options.hpp>
#include <kdet/results.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace kdet {

using ObjectId = std::uint32_t;

struct LocateOptions;       // locate.hpp
struct LocateResult;        // locate.hpp
struct DeviceLocateResults; // locate.hpp

/// @brief The most rings Detector::set_self_exclusion_rings() takes: each tet's list of excluded tets
/// grows with the cube of the rings (a few thousand tets per tet at this bound in a typical mesh).
constexpr int max_exclusion_rings = 4;

/// @brief An object's collision group and mask (Detector::set_collision_filter).
struct CollisionFilter {
    std::uint32_t group = 1;
    std::uint32_t mask = ~0u;
};

/// @brief Vertex positions as they lie in the caller's memory: coordinate k (0: x, 1: y, 2: z) of
/// vertex v is element `v * row_stride + k * column_stride` of `data`, float32 or float64 (strides
/// in elements, not bytes; any sign, zero included, as NumPy's strides divided by the item size).
/// The defaults describe x y z per vertex, contiguous: a C-ordered (n, 3) array. A Fortran-ordered
/// one has row_stride 1 and column_stride n; every other row of a C-ordered one, row_stride 6.
struct PositionsView {
    const void* data = nullptr;
    bool is_double = false; ///< float64 elements, else float32
    std::size_t vertex_count = 0;
    std::ptrdiff_t row_stride = 3;
    std::ptrdiff_t column_stride = 1;
};

/// @brief Keeps objects and buffers between frames. Typical use:
/// add objects once, then each frame set_positions() for the objects that moved and detect().
///
/// Semantics: two tets collide when their closed sets share a point. Within one object, tets that
/// share a vertex index are adjacent and never reported (nor, where asked for, tets within a few
/// rings of each other and pairs touching at rest: set_self_exclusion_rings, exclude_rest_contacts). Positions are stored as float32.
/// Every finite float32 coordinate is accepted and answered exactly by NarrowPhase::exact with every
/// method, from subnormal values to the largest float and far from the origin; a scene scaled by a
/// power of two (exactly, no coordinate becoming subnormal) gives the same pairs with every method and
/// test. Non-finite coordinates, and doubles beyond float range, are refused with a kdet::Error naming
/// the object and vertex.
/// By default every pair of different objects is checked and self-collision is off.
/// A moved-from detector may only be destroyed or assigned to.
class Detector {
public:
    explicit Detector(const DetectorOptions& options = {});
    ~Detector();
    Detector(Detector&&) noexcept;
    Detector& operator=(Detector&&) noexcept;
    Detector(const Detector&) = delete;
    Detector& operator=(const Detector&) = delete;

    /// @brief Adds an object; tets are 4 vertex indices (0-based) each. Throws kdet::Error on an
    /// out-of-range index, a non-finite coordinate or more than 2^29 - 1 tets in all objects, and
    /// then leaves the detector unchanged.
    /// Internally the tets are stored in the spatial order of these positions (neighbours close in
    /// memory), so pass the object's real rest shape; results always use the tet order given here.
    ObjectId add_object(const float* positions, std::size_t vertex_count, const std::uint32_t* tets,
                        std::size_t tet_count);
    ObjectId add_object(const double* positions, std::size_t vertex_count, const std::uint32_t* tets,
                        std::size_t tet_count);
    ObjectId add_object(const TetMesh& mesh);
    /// @brief add_object() from host positions in any layout (PositionsView).
    ObjectId add_object(const PositionsView& positions, const std::uint32_t* tets, std::size_t tet_count);

    /// @brief Replaces an object's vertex positions (x y z per vertex, same count as when added).
    /// Throws kdet::Error on a wrong vertex count or a non-finite coordinate (or one beyond float
    /// range), and then keeps the object's previous positions.
    void set_positions(ObjectId object, const float* positions, std::size_t vertex_count);
    void set_positions(ObjectId object, const double* positions, std::size_t vertex_count);
    /// @brief set_positions() from host memory in any layout (PositionsView), read where it lies:
    /// a strided or float64 array needs no contiguous copy first. Also throws kdet::Error on null
    /// data or strides whose extent overflows.
    void set_positions(ObjectId object, const PositionsView& positions);

    /// @brief Replaces an object's positions from memory of the detector's backend (a CUDA device
    /// pointer for Backend::cuda, a host pointer for Backend::cpu), e.g. a simulation's own buffer;
    /// nothing passes through the host and nothing waits. The positions are copied now (on
    /// Backend::cuda in the order of DetectorOptions::cuda_stream, after the kernels enqueued on it
    /// so far) and checked by the next detection, on the backend: if one is not finite, that
    /// detection uses none of the positions given this way, keeps the objects' previous ones, and its
    /// detect() or finish() throws kdet::Error naming the object and vertex. Throws at once on a wrong
    /// vertex count, null data, strides whose extent overflows, or (Backend::cuda) memory of another
    /// CUDA device than the detector's, or pageable host memory on a GPU that cannot read it.
    /// The first form takes x y z float per vertex; the second any layout, float32 or float64 (a
    /// strided or float64 array is gathered into float32 by the backend, on the same stream).
    void set_positions_on_device(ObjectId object, const float* positions, std::size_t vertex_count);
    void set_positions_on_device(ObjectId object, const PositionsView& positions);

    /// @brief Switches self-collision of one object (off by default).
    void set_self_collision(ObjectId object, bool enabled);
    /// @brief Switches collision between two different objects (on by default). The switch wins over
    /// the collision filters: the last set_pair_collision() of a pair decides it, whatever
    /// set_collision_filter() says before or after.
    void set_pair_collision(ObjectId a, ObjectId b, bool enabled);
    /// @brief Marks an object static (or moving again; all are moving by default). A static object is
    /// placed into a grid of its own once, at the next detection, and kept there across frames, so a
    /// frame's cost follows the moving tets; set_positions() on it places it again at the next
    /// detection. Pairs of two static objects, and a static object's self-collision, are never
    /// reported (as in PhysX: they cannot change); a static object collides with the moving objects
    /// it is checked against as any object does. Changing the flag costs a rebuild, as add_object does.
    void set_static(ObjectId object, bool is_static);
    /// @brief Whether set_static() marked the object static.
    bool is_static(ObjectId object) const;

    /// @brief Sets an object's collision filter, as PhysX's filter data and MuJoCo's contype and
    /// conaffinity: two different objects a and b are checked when (group_a & mask_b) != 0 and
    /// (group_b & mask_a) != 0. Objects start in group 1 with every mask bit set, so by default every
    /// pair is checked. A pair switched by set_pair_collision() keeps its switch; self-collision is
    /// set_self_collision()'s alone. Pairs left out are skipped by the search itself, before any test.
    void set_collision_filter(ObjectId object, std::uint32_t group, std::uint32_t mask);
    CollisionFilter collision_filter(ObjectId object) const;

    /// @brief Within one object, leaves out tets that have vertices within `rings` mesh edges of each
    /// other, besides those sharing a vertex (`rings` = 0, the default, leaves out only those), for
    /// meshes whose neighbouring elements come close by design. The detector keeps, per tet, the sorted
    /// list of the later tets this adds (each pair once), which the search consults before any test; it
    /// grows with the cube of `rings`. The lists are built on the detector's backend, after a pending
    /// detect_async() frame. Throws kdet::Error for `rings` outside [0, max_exclusion_rings]. Kept
    /// across set_tets() (the lists are made again for the new tets).
    void set_self_exclusion_rings(ObjectId object, int rings);
    int self_exclusion_rings(ObjectId object) const;

    /// @brief Records the pairs of tets that collide at the current positions (those given to
    /// add_object() until set_positions() changes them) inside `object`, or between `object` and
    /// `other`, and never reports them again (a mesh that touches itself or another by design).
    /// Recorded whether or not the pair is switched on; calls add up. The pairs are found with this
    /// detector's narrow-phase test. set_tets() or remove_object() of either object forgets them.
    /// Returns how many pairs were recorded.
    std::size_t exclude_rest_contacts(ObjectId object);
    std::size_t exclude_rest_contacts(ObjectId object, ObjectId other);

    /// @brief Removes an object. Its id is not given again, and any later call naming it throws
    /// kdet::Error; the other objects keep their ids and everything set for them. Tets stay numbered
    /// per object in results; the global numbering (first_tet()) closes the gap from the next
    /// detection on.
    void remove_object(ObjectId object);

    /// @brief Replaces an object's tets (cutting, tearing, fracture, remeshing), keeping its vertices,
    /// or with `positions` its vertices too (their count may change). Results use the new numbering
    /// from the next detection on; the other objects keep their state. The object keeps its switches,
    /// filter and rings, and forgets its rest contacts. Throws kdet::Error on an out-of-range vertex
    /// index or a bad coordinate, as add_object() does, and then leaves the detector as it was.
    void set_tets(ObjectId object, const std::uint32_t* tets, std::size_t tet_count);
    void set_tets(ObjectId object, const std::uint32_t* tets, std::size_t tet_count, const PositionsView& positions);
    void set_tets(ObjectId object, const TetMesh& mesh);

    /// @brief Whether `object` names an object that was added and not removed.
    bool contains(ObjectId object) const;

    /// @brief Runs one detection; the result stays valid until the next call. The same as
    /// detect_async() followed by finish(): once a detector's buffers have grown (after its first
    /// frame), the host waits for the backend once per call (FrameCounts::host_waits).
    const FrameResult& detect();

    /// @brief Starts one detection and returns without waiting for the backend: on Backend::cuda every
    /// kernel and copy is enqueued on DetectorOptions::cuda_stream, so the host can prepare the
    /// simulation's next step meanwhile. A detector's first frame (and the first after objects were
    /// added) still reads a few sizes back to size its buffers. On Backend::cpu the work is done before
    /// it returns. Call finish() before reading any result, device_results() included.
    /// While the frame is pending every other call is allowed: set_positions, the switches and filters
    /// and add_object take effect from the next frame (finish() returns the frame as it was started);
    /// detect_async, detect, set_tets, remove_object, exclude_rest_contacts and locate finish it first.
    void detect_async();

    /// @brief Completes the detection detect_async() started: waits for it once, checks that every
    /// buffer was large enough (if not, grows it and runs the frame again, so no pair is ever lost),
    /// and returns the result, as detect() does. After it, device_results() holds the frame's pairs
    /// and flags, and work the caller enqueues on the stream sees them. Without a pending frame it
    /// returns the last result.
    const FrameResult& finish();

    /// @brief The last detection's pairs, flags and contacts in the backend's memory. Throws
    /// kdet::Error while a detect_async() frame is not finished.
    DeviceResults device_results() const;
    /// @brief Point location (locate.hpp) in `object`'s tets, or every object's (all_objects), at the
    /// positions as last set: for each point every tet that holds it. The points are host memory;
    /// with locate_on_device(), memory of the detector's backend (as set_positions_on_device()).
    /// The result stays valid until the next locate(). Throws kdet::Error on a non-finite point, a bad
    /// object or option, or positions handed over on the device that no detect() has checked yet.
    const LocateResult& locate(const PositionsView& points, ObjectId object, const LocateOptions& options);
    const LocateResult& locate(const PositionsView& points, ObjectId object);
    const LocateResult& locate_on_device(const PositionsView& points, ObjectId object, const LocateOptions& options);
    /// @brief The last locate()'s results in the backend's memory.
    DeviceLocateResults device_locate_results() const;

    /// @brief Global id of the first tet of `object` (see DeviceResults): objects are numbered one after
    /// the other in id order, removed ones holding no tets. After remove_object() or set_tets() it gives
    /// the numbering of the next detection.
    std::uint32_t first_tet(ObjectId object) const;

    /// @brief The ids given so far (removed objects included: ids index FrameResult::colliding, where a
    /// removed object has no flags).
    std::size_t object_count() const;
    std::size_t tet_count(ObjectId object) const;
    /// @brief Bytes held by the detector's buffers (device memory on the CUDA backend).
    std::size_t memory_bytes() const;
    /// @brief The CPU model or GPU name the detector runs on.
    std::string device_name() const;
    const DetectorOptions& options() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    // The one-off point location hands its detector's result over instead of copying it.
    friend LocateResult locate(const TetMesh& mesh, const PositionsView& points, const LocateOptions& options,
                               const DetectorOptions& detector_options);
};

/// @brief A pair of tet indices (in file order) of a one-off query.
using IndexPair = std::pair<std::uint32_t, std::uint32_t>;

/// @brief All colliding pairs (i in a, j in b), sorted ascending. Throws kdet::Error for
/// Method::kdet_no_pairs, which builds no pairs (Detector::detect() gives its flags), and for options
/// whose results this cannot return: results_to_host = false, contacts, distances.
std::vector<IndexPair> collide(const TetMesh& a, const TetMesh& b, const DetectorOptions& options = {});

/// @brief All colliding pairs i < j inside one mesh (self-collision), sorted ascending. Throws
/// kdet::Error for the options collide() refuses.
std::vector<IndexPair> collide_self(const TetMesh& mesh, const DetectorOptions& options = {});

/// @brief True when the CUDA backend can run here; otherwise `reason` (if given) says why not.
bool cuda_available(std::string* reason = nullptr);

/// @brief The version string, with the git commit it was built from when known.
std::string version();

} // namespace kdet
