#include "commands.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/io.hpp>
#include <kdet/locate.hpp>
#include <kdet/option_table.hpp>

#include <cfloat>
#include <cstdio>
#include <fstream>
#include <iostream>

namespace kdet::cli {

namespace {

const char* locate_help = R"(usage: kdet locate MESH POINTS --out FILE [--within D] [options]

For each point of POINTS, every tetrahedron of MESH whose closed set holds it (decided exactly for
the float32 coordinates; a point on a shared face, edge or vertex gets every tet holding it).
POINTS is a text file of 'x y z' lines ('#' starts a comment) or any mesh file, whose vertices are
the points. FILE gets one line per (point, tet): 'point tet b0 b1 b2 b3' (0-based indices in file
order, sorted; b: barycentric coordinates of the point in the tet's vertices as listed).

options:
  --out FILE           where the lines go (required)
  --within D           a point no tet holds gets the nearest tet at distance <= D: its line gives
                       the barycentric coordinates of the tet's closest point; every line ends
                       with 'distance' (0 where the tet holds the point)
  --allow-degenerate   accept zero-volume tetrahedra (rejected by default)
)";

/// @brief --within's value: a finite distance >= 0, the whole text a number.
double parse_within(const std::string& text) {
    return parse_number("--within", text, 0.0, DBL_MAX, "a finite distance >= 0");
}

void write_hits(const std::string& path, const LocateResult& r, bool with_distance) {
    std::ofstream out(path);
    if (!out) throw Error(path + ": cannot open file for writing");
    out.precision(17);
    for (std::size_t p = 0; p < r.point_count; ++p)
        for (std::uint64_t h = r.offsets[p]; h < r.offsets[p + 1]; ++h) {
            out << p << ' ' << r.tets[h];
            for (int k = 0; k < 4; ++k) out << ' ' << r.barycentrics[4 * h + k];
            if (with_distance) out << ' ' << r.distances[h];
            out << '\n';
        }
    out.flush();
    if (!out) throw Error(path + ": write failed");
}

} // namespace

int run_locate(int argc, char** argv) {
    DetectorOptions options;
    std::vector<std::string> inputs;
    bool help = false;
    std::string out_path;
    LocateOptions locate_options;
    ReadOptions read_options;

    CommandLine parser("locate");
    parser.positionals(2, inputs);
    parser.flag("--allow-degenerate", read_options.allow_degenerate);
    parser.flag("--help", help);
    parser.option("--out", "FILE", [&](const std::string& v) { out_path = v; });
    parser.option("--within", "D", [&](const std::string& v) { locate_options.within = parse_within(v); });
    parser.detector_options(options, front_end_locate);
    parser.parse(argc, argv, 2);
    if (help) {
        std::cout << locate_help << detector_options_help(front_end_locate);
        return exit_ok;
    }
    if (inputs.size() < 2) throw UsageError("locate: expected a mesh and a points file (see 'kdet locate --help')");
    if (out_path.empty()) throw UsageError("locate: missing --out FILE");

    const TetMesh mesh = read_tet_mesh(inputs[0], read_options);
    const std::vector<double> points = read_points(inputs[1]);
    const LocateResult result = locate(mesh, points, locate_options, options);
    write_hits(out_path, result, locate_options.within > 0);
    // A point's hits either hold it (distance 0) or, with --within, are its one nearest tet.
    std::size_t held = 0, near = 0;
    for (std::size_t p = 0; p < result.point_count; ++p) {
        if (result.offsets[p + 1] == result.offsets[p]) continue;
        ++(result.distances[result.offsets[p]] > 0.0 ? near : held);
    }
    std::printf("points %zu, located %zu", result.point_count, held + near);
    if (locate_options.within > 0) std::printf(" (%zu in a tet, %zu near one)", held, near);
    std::printf(", (point, tet) lines %zu\n", result.hit_count);
    return exit_ok;
}

} // namespace kdet::cli
