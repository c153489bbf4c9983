/// @file prepare_command.cpp
/// @brief `kdet prepare`: argument parsing and the table of prepared meshes.

#include "prepare_command.hpp"

#include "cli_args.hpp"
#include "prepare_pipeline.hpp"

#include <kdet/error.hpp>
#include <kdet/io.hpp>
#include <kdet/prepare.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

namespace kdet::cli {
namespace {

const char* prepare_help = R"(usage: kdet prepare [MODEL...] [-r N]... [--force] [--verbose]
       kdet prepare --surface FILE --tets N --out STEM [--verbose]

Makes the tetrahedral meshes of the thesis scenes from the triangle surfaces in the data folder
($KDET_DATA_DIR, default ../shared/models): each surface is centred and scaled to a largest extent
of 1, closed with CGAL's 3D alpha wrapping, and tetrahedralized with TetGen -pq; alpha is searched
until the tet count is within 3 % of thesis Table 5.2 (10 % at worst). The meshes go to the cache
($KDET_CACHE_DIR, else $XDG_CACHE_HOME/kdet, else ~/.cache/kdet) and are rebuilt only when the
surface, the parameters or the tools (CGAL, the tetgen program) change.

  MODEL            armadillo, happy-buddha, max-planck, bunny (default: all four)
  -r N             resolution 1-4; repeat for several (default: all four)
  --force          rebuild even what is cached
  --verbose        print every alpha tried
  --surface FILE   any triangle surface (OBJ, OFF, STL or PLY; holes and self-intersections are
                   fine) to a TetGen mesh STEM.node/STEM.ele of about --tets N tets, in the surface's
                   own coordinates; nothing is cached
)";

int prepare_surface(const std::string& surface_path, long long tets, const std::string& out, bool verbose) {
    const auto start = std::chrono::steady_clock::now();
    const TriangleMesh surface = read_surface(surface_path);
    const std::string work = out + ".work";
    const prepare::SizedMesh sized =
        prepare::tetrahedralize(surface, static_cast<std::size_t>(tets), work, {}, verbose ? &std::cout : nullptr);
    std::filesystem::remove_all(work);
    write_tetgen(sized.mesh, out);
    std::printf("%s: %zu tets (target %lld), alpha = diagonal / %.4g, %d wraps, %.1f s -> %s.node, %s.ele\n",
                surface_path.c_str(), sized.mesh.num_tets(), tets, 1.0 / sized.alpha, sized.wraps,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), out.c_str(),
                out.c_str());
    return 0;
}

} // namespace

int run_prepare(int argc, char** argv) {
    std::vector<std::string> models;
    std::vector<int> resolutions;
    bool force = false, verbose = false, help = false;
    std::string surface, out;
    long long tets = 0;

    CommandLine parser("prepare");
    parser.positionals(thesis_models().size(), models);
    parser.flag("--help", help);
    parser.flag("--force", force);
    parser.flag("--verbose", verbose);
    parser.option("-r", "resolution", [&](const std::string& v) { resolutions.push_back(static_cast<int>(parse_integer("-r", v, 1, 4))); });
    parser.option("--surface", "FILE", [&](const std::string& v) { surface = v; });
    parser.option("--tets", "N", [&](const std::string& v) { tets = parse_integer("--tets", v, 1, 100000000); });
    parser.option("--out", "STEM", [&](const std::string& v) { out = v; });
    parser.parse(argc, argv, 2);
    if (help) {
        std::cout << prepare_help;
        return 0;
    }
    if (!surface.empty() || tets != 0 || !out.empty()) {
        if (surface.empty() || tets == 0 || out.empty())
            throw UsageError("prepare: --surface, --tets and --out go together");
        if (!models.empty() || !resolutions.empty() || force)
            throw UsageError("prepare: --surface takes no MODEL, -r or --force");
        return prepare_surface(surface, tets, out, verbose);
    }

    std::vector<std::string> known;
    for (const ModelInfo& model : thesis_models()) known.push_back(model.name);
    try {
        for (std::string& model : models) model = parse_choice("MODEL", model, known);
    } catch (const Error& e) {
        throw UsageError(std::string("prepare: ") + e.what());
    }
    if (models.empty()) models = known;
    if (resolutions.empty()) resolutions = {1, 2, 3, 4};
    // Each mesh once, in the order asked for, however often it was named.
    const auto drop_repeats = [](auto& values) {
        for (std::size_t i = 0; i < values.size(); ++i)
            values.erase(std::remove(values.begin() + static_cast<std::ptrdiff_t>(i) + 1, values.end(), values[i]),
                         values.end());
    };
    drop_repeats(models);
    drop_repeats(resolutions);

    std::printf("cache: %s\n%-13s %3s %8s %8s %7s %11s %8s  %s\n", cache_dir().c_str(), "model", "res", "target",
                "tets", "diff", "diag/alpha", "seconds", "status");
    for (const std::string& name : models) {
        for (const int resolution : resolutions) {
            std::fflush(stdout);
            const prepare::Prepared prepared =
                prepare::prepare_model(thesis_model(name), resolution, force, verbose ? &std::cout : nullptr);
            const std::size_t target = target_tets(name, resolution);
            std::printf("%-13s %3d %8zu %8zu %+6.1f%% %11.2f %8.1f  %s\n", name.c_str(), resolution, target,
                        prepared.record.tets,
                        100.0 * (static_cast<double>(prepared.record.tets) / static_cast<double>(target) - 1.0),
                        1.0 / prepared.record.alpha,
                        prepared.record.seconds,
                        prepared.built ? ("built, " + std::to_string(prepared.wraps) + " wraps").c_str() : "cached");
        }
    }
    return 0;
}

} // namespace kdet::cli
