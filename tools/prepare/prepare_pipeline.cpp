/// @file prepare_pipeline.cpp
/// @brief The alpha search, the TetGen run and the cache of prepared thesis models.

#include "prepare_pipeline.hpp"

#include "alpha_wrap.hpp"

#include <kdet/error.hpp>
#include <kdet/io.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <system_error>
#include <unistd.h>

namespace kdet::prepare {
namespace {

namespace fs = std::filesystem;

// The wrap lies this fraction of alpha outside the input: thin enough to keep the shape, thick enough
// that the wrap stays cheap (CGAL's examples use a similar ratio).
constexpr double kOffsetPerAlpha = 1.0 / 30.0;
// Tet count ~ (diagonal / alpha)^p; p is about 1.6 on the thesis models, and first guesses use it.
constexpr double kCountExponent = 1.6;
// A first guess measured on the armadillo: diagonal / alpha = 30 gives about 30'000 tets.
constexpr double kReferenceRatio = 30.0;
constexpr double kReferenceTets = 30000.0;
// The coarse wrap that closes holes; the thesis models keep their shape at this alpha.
constexpr double kClosingRatio = 15.0;
// A wrap enclosing less than this fraction of the coarse wrap's volume went inside through a hole.
constexpr double kLeakVolumeFraction = 0.5;
// Bumped whenever the pipeline changes what it produces, so that old cache entries are rebuilt.
constexpr const char* kPipelineVersion = "kdet-prepare 2";
constexpr const char* kTetgenSwitches = "-pq";

std::string quoted(const std::string& text) {
    std::string out = "'";
    for (const char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

/// @brief The bounding box of a surface's vertices.
struct Box {
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL};
    double hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    double extent(int axis) const { return hi[axis] - lo[axis]; }
};

Box box_of(const TriangleMesh& surface) {
    Box box;
    for (std::size_t i = 0; i < surface.positions.size(); ++i) {
        box.lo[i % 3] = std::min(box.lo[i % 3], surface.positions[i]);
        box.hi[i % 3] = std::max(box.hi[i % 3], surface.positions[i]);
    }
    return box;
}

/// @brief The volume a closed surface encloses (by the divergence theorem). A wrap that slipped
/// through a hole into the inside is a thin double shell and encloses next to nothing.
double enclosed_volume(const TriangleMesh& surface) {
    double six_volume = 0.0;
    const std::vector<double>& p = surface.positions;
    for (std::size_t t = 0; t < surface.num_triangles(); ++t) {
        const double* a = &p[3 * surface.triangles[3 * t]];
        const double* b = &p[3 * surface.triangles[3 * t + 1]];
        const double* c = &p[3 * surface.triangles[3 * t + 2]];
        six_volume += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                      a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    return std::abs(six_volume) / 6.0;
}

void write_off(const TriangleMesh& surface, const std::string& path) {
    std::ofstream out(path);
    out << "OFF\n" << surface.num_vertices() << ' ' << surface.num_triangles() << " 0\n" << std::setprecision(17);
    for (std::size_t v = 0; v < surface.num_vertices(); ++v)
        out << surface.positions[3 * v] << ' ' << surface.positions[3 * v + 1] << ' ' << surface.positions[3 * v + 2]
            << '\n';
    for (std::size_t t = 0; t < surface.num_triangles(); ++t)
        out << "3 " << surface.triangles[3 * t] << ' ' << surface.triangles[3 * t + 1] << ' '
            << surface.triangles[3 * t + 2] << '\n';
    if (!out.flush()) throw Error(path + ": cannot write file");
}

std::string tail_of(const std::string& path) {
    std::ifstream in(path);
    std::string line, last;
    while (std::getline(in, line))
        if (!line.empty()) last = line;
    return last.empty() ? "no output" : last;
}

/// @brief Runs TetGen -pq on a closed surface and reads its tets.
TetMesh run_tetgen(const std::string& tetgen, const TriangleMesh& closed, const std::string& work_dir) {
    const std::string input = (fs::path(work_dir) / "surface.off").string();
    const std::string log = (fs::path(work_dir) / "tetgen.log").string();
    write_off(closed, input);
    // Q only silences TetGen; the mesh depends on p and q alone.
    const std::string command =
        quoted(tetgen) + " " + kTetgenSwitches + "Q " + quoted(input) + " > " + quoted(log) + " 2>&1";
    if (std::system(command.c_str()) != 0)
        throw Error("tetgen " + std::string(kTetgenSwitches) + " failed on " + input + ": " + tail_of(log));
    return read_tetgen((fs::path(work_dir) / "surface.1").string());
}

std::string mesh_key(const ModelInfo& model, const std::string& source_hash, std::size_t target,
                     const SearchLimits& limits) {
    std::ostringstream parameters;
    parameters << kPipelineVersion << "|model=" << model.name << "|source=" << source_hash << "|target=" << target
               << "|aim=" << limits.aim << "|tolerance=" << limits.tolerance << "|max_wraps=" << limits.max_wraps
               << "|offset_per_alpha=" << kOffsetPerAlpha << "|closing_ratio=" << kClosingRatio
               << "|leak_fraction=" << kLeakVolumeFraction << "|normalize=unit-extent|cgal=" << cgal_version()
               << "|tetgen=" << file_hash(find_tetgen()) << "|switches=" << kTetgenSwitches;
    return content_hash(parameters.str());
}

bool in_cache(const std::string& record_path, const std::string& key) {
    std::error_code ignored;
    if (!fs::is_regular_file(record_path, ignored)) return false;
    try {
        const PreparedRecord record = read_prepared_record(record_path);
        const std::string stem = prepared_mesh_stem(key);
        return record.key == key && fs::is_regular_file(stem + ".node", ignored) &&
               fs::is_regular_file(stem + ".ele", ignored);
    } catch (const Error&) {
        return false;  // a damaged record is rebuilt
    }
}

} // namespace

std::string find_tetgen() {
    const char* path = std::getenv("PATH");
    std::istringstream dirs(path != nullptr ? path : "");
    std::string dir;
    while (std::getline(dirs, dir, ':')) {
        if (dir.empty()) continue;
        const fs::path candidate = fs::path(dir) / "tetgen";
        if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    }
    throw Error("tetgen not found on PATH (install the Debian package tetgen)");
}

void normalize(TriangleMesh& surface) {
    const Box box = box_of(surface);
    const double extent = std::max({box.extent(0), box.extent(1), box.extent(2)});
    if (!(extent > 0.0)) throw Error("surface has no extent");
    for (std::size_t i = 0; i < surface.positions.size(); ++i)
        surface.positions[i] = (surface.positions[i] - 0.5 * (box.lo[i % 3] + box.hi[i % 3])) / extent;
}

SizedMesh tetrahedralize(const TriangleMesh& surface, std::size_t target_tets, const std::string& work_dir,
                         const SearchLimits& limits, std::ostream* log) {
    if (target_tets == 0) throw Error("the target tet count must be positive");
    const std::string tetgen = find_tetgen();
    fs::create_directories(work_dir);
    const Box box = box_of(surface);
    const double diagonal = std::hypot(box.extent(0), box.extent(1), box.extent(2));
    const double target = static_cast<double>(target_tets);

    // Searches r = diagonal / alpha by secant steps on log(tets) over log(r), kept inside the bracket
    // of tries that fell short and tries that overshot.
    double ratio = kReferenceRatio * std::pow(target / kReferenceTets, 1.0 / kCountExponent);
    double below = 0.0, above = HUGE_VAL;  // ratios known to give too few / too many tets
    double previous_ratio = 0.0, previous_error = 0.0;
    SizedMesh best;
    double best_error = HUGE_VAL;
    // Holes wider than alpha let the wrap inside. A coarse wrap closes them; once a fine wrap of the
    // input encloses much less than it, the fine wraps are taken of the coarse wrap instead.
    const double closing_alpha = diagonal / kClosingRatio;
    const TriangleMesh closed = alpha_wrap(surface, closing_alpha, kOffsetPerAlpha * closing_alpha);
    const double closed_volume = enclosed_volume(closed);
    bool leaks = false;
    for (int wrap = 1; wrap <= limits.max_wraps; ++wrap) {
        const double alpha = diagonal / ratio;
        TriangleMesh wrapped = alpha_wrap(leaks ? closed : surface, alpha, kOffsetPerAlpha * alpha);
        if (!leaks && enclosed_volume(wrapped) < kLeakVolumeFraction * closed_volume) {
            if (log != nullptr) *log << "  the wrap slips through holes at alpha = diagonal / " << ratio
                                     << "; wrapping the closed coarse wrap instead\n";
            leaks = true;
            wrapped = alpha_wrap(closed, alpha, kOffsetPerAlpha * alpha);
        }
        TetMesh mesh = run_tetgen(tetgen, wrapped, work_dir);
        const double count = static_cast<double>(mesh.num_tets());
        const double error = std::log(count / target);
        if (log != nullptr)
            *log << "  try " << wrap << ": alpha = diagonal / " << std::setprecision(5) << ratio << " -> "
                 << mesh.num_tets() << " tets (" << std::showpos << std::setprecision(3) << 100.0 * (count / target - 1.0)
                 << std::noshowpos << " %)\n";
        if (std::abs(error) < best_error) {
            best_error = std::abs(error);
            best = {std::move(mesh), 1.0 / ratio, wrap};
        }
        if (std::abs(count / target - 1.0) <= limits.aim) break;
        (count < target ? below : above) = ratio;
        double slope = kCountExponent;
        if (previous_ratio > 0.0 && ratio != previous_ratio)
            slope = std::clamp((error - previous_error) / std::log(ratio / previous_ratio), 0.5, 4.0);
        previous_ratio = ratio;
        previous_error = error;
        ratio *= std::exp(-error / slope);
        if (!(ratio > below && ratio < above)) ratio = above == HUGE_VAL ? 2.0 * below : std::sqrt(below * above);
    }
    best.wraps = std::max(best.wraps, 1);
    if (std::exp(best_error) - 1.0 > limits.tolerance && 1.0 - std::exp(-best_error) > limits.tolerance)
        throw Error("no alpha gave a tet count within " + std::to_string(static_cast<int>(100 * limits.tolerance)) +
                    " % of " + std::to_string(target_tets) + " (closest: " + std::to_string(best.mesh.num_tets()) + ")");
    return best;
}

Prepared prepare_model(const ModelInfo& model, int resolution, bool force, std::ostream* log) {
    const std::size_t target = target_tets(model.name, resolution);
    const std::string source = data_path(model.source_file);
    const std::string source_hash = file_hash(source);
    const SearchLimits limits;
    const std::string key = mesh_key(model, source_hash, target, limits);
    const std::string record_path = prepared_record_path(model.name, resolution);
    Prepared result;
    if (!force && in_cache(record_path, key)) {
        result.record = read_prepared_record(record_path);
        return result;
    }

    const auto start = std::chrono::steady_clock::now();
    TriangleMesh surface = read_surface(source);
    normalize(surface);
    // A folder per process, so that two `kdet prepare` runs never share TetGen's files.
    const fs::path work = fs::path(cache_dir()) / "work" / (key + "-" + std::to_string(::getpid()));
    SizedMesh sized = tetrahedralize(surface, target, work.string(), limits, log);
    const std::string stem = prepared_mesh_stem(key);
    fs::create_directories(fs::path(stem).parent_path());
    write_tetgen(sized.mesh, (work / "final").string());
    // The record is written last: a run that stops half-way leaves no record pointing at a half mesh.
    fs::rename(work / "final.node", stem + ".node");
    fs::rename(work / "final.ele", stem + ".ele");
    fs::remove_all(work);

    result.record.model = model.name;
    result.record.resolution = resolution;
    result.record.source_hash = source_hash;
    result.record.key = key;
    result.record.tets = sized.mesh.num_tets();
    result.record.alpha = sized.alpha;
    result.record.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    write_prepared_record(result.record, record_path);
    result.built = true;
    result.wraps = sized.wraps;
    return result;
}

} // namespace kdet::prepare
