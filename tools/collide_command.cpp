#include "commands.hpp"
#include "exact_check.hpp"
#include "mpi_commands.hpp"

#include <kdet/detector.hpp>
#include <kdet/error.hpp>
#include <kdet/io.hpp>
#include <kdet/option_table.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>

namespace kdet::cli {

namespace {

const char* collide_help = R"(usage: kdet collide A [B] [options]

Reports the colliding tetrahedron pairs between meshes A and B, or inside A with --self
(with --margin D, every pair at most D apart: the summary counts them, and with --distances
how many of them overlap).
A and B are tet meshes: TetGen (name, name.node or name.ele), MEDIT .mesh, Gmsh .msh (2.2 or 4.1)
or legacy VTK .vtk (4.x or 5.1); these two ASCII or binary.
Tetrahedra of one mesh that share a vertex are adjacent and never reported.

options:
  --self               self-collision of A (give one mesh)
  --exclusion-rings K  with --self, also leave out tets with vertices within K mesh edges of
                       each other (0-4; 0, the default, leaves out only tets sharing a vertex)
  --pairs FILE         write 'i j' per line: 0-based tet indices in file order, sorted
  --contacts FILE      write 'i j depth nx ny nz' per pair: moving B's tet j by depth along
                       (nx, ny, nz) separates it from A's tet i (from the 44-axis SAT); with
                       --margin, a pair that does not overlap reads 'i j 0 0 0 0'
  --distances FILE     write 'i j distance ax ay az bx by bz' per pair: the distance and a closest
                       point on A's tet i, then on B's tet j (a common point when they intersect)
  --check-exact        judge the chosen test against CGAL's exact predicates and print its
                       false positives and false negatives on these meshes
  --json               print one JSON object instead of text
  --allow-degenerate   accept zero-volume tetrahedra (rejected by default)
  --mpi                run on the ranks of mpirun (kdet::mpi): rank 0 reads the meshes, splits them
                       over the ranks and writes the pairs all ranks found
  --partition P        with --mpi: slabs (along the longest axis, default) or random
)";

/// @brief @p value on one line with ", " and ": " between items, as kdet has always printed it
/// (nlohmann/json writes either no spaces or one item per line). A line break in the dump is always
/// structure: line breaks inside strings are escaped.
std::string one_line(const nlohmann::ordered_json& value) {
    const std::string lines = value.dump(0);
    std::string out;
    for (std::size_t i = 0; i < lines.size(); ++i)
        if (lines[i] != '\n') out += lines[i];
        else if (i > 0 && lines[i - 1] == ',') out += ' ';
    return out;
}

/// @brief Milliseconds to the nanosecond, printed as such rather than with the binary fraction's tail.
double milliseconds(double value) { return std::round(value * 1e6) / 1e6; }

/// @brief What follows a pair's indices in write_pair_lines.
enum class PairColumns { none, contacts, distances };

/// @brief Writes one line per colliding pair; with contacts, depth and direction follow the indices,
/// with distances the distance and the two closest points.
void write_pair_lines(const std::string& path, const FrameResult& result, PairColumns columns) {
    std::ofstream out(path);
    if (!out) throw Error(path + ": cannot open file for writing");
    out.precision(9);
    for (std::size_t k = 0; k < result.pairs.size(); ++k) {
        out << result.pairs[k].tet_a << ' ' << result.pairs[k].tet_b;
        if (columns == PairColumns::contacts) {
            const Contact& c = result.contacts[k];
            out << ' ' << c.depth << ' ' << c.direction[0] << ' ' << c.direction[1] << ' ' << c.direction[2];
        } else if (columns == PairColumns::distances) {
            const ClosestPoints& p = result.closest_points[k];
            out << ' ' << result.distances[k];
            for (float x : p.on_a) out << ' ' << x;
            for (float x : p.on_b) out << ' ' << x;
        }
        out << '\n';
    }
    out.flush();
    if (!out) throw Error(path + ": write failed");
}

void print_examples(const char* what, const std::vector<IndexPair>& pairs) {
    std::printf("  %-16s %zu", what, pairs.size());
    for (std::size_t k = 0; k < pairs.size() && k < 5; ++k) std::printf("%s(%u, %u)", k ? " " : "  e.g. ", pairs[k].first, pairs[k].second);
    std::printf("\n");
}

} // namespace

int run_collide(int argc, char** argv) {
    DetectorOptions options;
    std::vector<std::string> meshes;
    bool self = false, json = false, help = false, check = false, mpi = false;
    std::string pairs_path, contacts_path, distances_path, partition;
    ReadOptions read_options;
    int rings = 0;

    CommandLine parser("collide");
    parser.positionals(2, meshes);
    parser.flag("--self", self);
    parser.flag("--json", json);
    parser.flag("--allow-degenerate", read_options.allow_degenerate);
    parser.flag("--help", help);
    parser.option("--pairs", "FILE", [&](const std::string& v) { pairs_path = v; });
    parser.option("--contacts", "FILE", [&](const std::string& v) { contacts_path = v; });
    parser.option("--distances", "FILE", [&](const std::string& v) { distances_path = v; });
    parser.flag("--check-exact", check);
    parser.flag("--mpi", mpi);
    parser.option("--partition", "slabs|random", [&](const std::string& v) {
        partition = parse_choice("--partition", v, {"slabs", "random"});
    });
    parser.option("--exclusion-rings", "K", [&](const std::string& v) {
        rings = static_cast<int>(parse_integer("--exclusion-rings", v, 0, max_exclusion_rings));
    });
    parser.detector_options(options, front_end_cli);
    parser.parse(argc, argv, 2);
    if (help) {
        std::cout << collide_help << detector_options_help(front_end_cli);
        return exit_ok;
    }
    if (meshes.empty()) throw UsageError("collide: missing mesh A (see 'kdet collide --help')");
    if (self && meshes.size() == 2) throw UsageError("collide: --self takes one mesh, got two");
    if (!self && meshes.size() == 1) throw UsageError("collide: one mesh given: add mesh B, or --self for self-collision");
    if (rings > 0 && !self) throw UsageError("collide: --exclusion-rings acts within one mesh: it needs --self");
    if (rings > 0 && check)
        throw UsageError("collide: --check-exact judges every pair, so it cannot follow --exclusion-rings");
    if (options.method == Method::kdet_no_pairs &&
        (!pairs_path.empty() || !contacts_path.empty() || !distances_path.empty() || check))
        throw UsageError("collide: --pairs, --contacts, --distances and --check-exact need a method that builds pairs; "
                         "kdet_no_pairs only flags tets");
    if (check && options.margin > 0.0f)
        throw UsageError("collide: --check-exact judges intersections, not pairs within a margin; drop one of them");
    if (!partition.empty() && !mpi) throw UsageError("collide: --partition needs --mpi");
    if (mpi && (json || check || !contacts_path.empty() || !distances_path.empty() || rings > 0))
        throw UsageError("collide: --json, --contacts, --distances, --check-exact and --exclusion-rings do not work with --mpi");
    if (mpi) return run_collide_mpi({meshes, self, pairs_path, partition, read_options, options});
    std::string unavailable;
    if (check && !exact_check_available(&unavailable))
        throw UsageError("collide: --check-exact is not available: " + unavailable);
    options.contacts = !contacts_path.empty();
    options.distances = !distances_path.empty();

    const TetMesh a = read_tet_mesh(meshes[0], read_options);
    const TetMesh b = self ? TetMesh{} : read_tet_mesh(meshes[1], read_options);

    Detector detector(options);
    const ObjectId id_a = detector.add_object(a);
    if (self) {
        detector.set_self_collision(id_a, true);
        detector.set_self_exclusion_rings(id_a, rings);
    } else {
        detector.add_object(b);
    }
    const FrameResult& result = detector.detect();
    if (!pairs_path.empty()) write_pair_lines(pairs_path, result, PairColumns::none);
    if (!contacts_path.empty()) write_pair_lines(contacts_path, result, PairColumns::contacts);
    if (!distances_path.empty()) write_pair_lines(distances_path, result, PairColumns::distances);
    ExactReport exact;
    if (check) {
        std::vector<IndexPair> reported;
        for (const TetPair& p : result.pairs) reported.emplace_back(p.tet_a, p.tet_b);
        exact = check_exact(a, self ? nullptr : &b, reported, options);
    }

    const FrameCounts& c = result.counts;
    const StageTimes& t = result.times;
    if (json) {
        nlohmann::ordered_json out;
        out["mesh_a"] = meshes[0];
        out["tets_a"] = a.num_tets();
        if (!self) {
            out["mesh_b"] = meshes[1];
            out["tets_b"] = b.num_tets();
        }
        out["self"] = self;
        if (self) out["exclusion_rings"] = rings;
        for (const char* name : {"method", "test", "hash", "backend"}) out[name] = find_option(name)->text(options);
        out["margin"] = std::stod(find_option("margin")->text(options)); // as given, not widened from float
        out["candidates"] = c.candidates;
        out["narrow_phase_candidates"] = c.narrow_phase_candidates;
        out["colliding_pairs"] = c.colliding_pairs;
        if (options.margin > 0.0f && options.distances) out["overlapping_pairs"] = overlapping_pairs(result);
        out["colliding_tets"] = c.colliding_tets;
        out["buffer_regrows"] = c.buffer_regrows;
        out["host_waits"] = c.host_waits;
        out["exact_stage_pairs"] = c.exact_stage_pairs;
        out["times_ms"] = {{"bounding_boxes", milliseconds(t.bounding_boxes)},
                           {"populate_grid", milliseconds(t.populate_grid)},
                           {"find_candidates", milliseconds(t.find_candidates)},
                           {"sort_pairs", milliseconds(t.sort_pairs)},
                           {"narrow_phase", milliseconds(t.narrow_phase)}};
        out["total_ms"] = milliseconds(t.total);
        out["memory_bytes"] = result.memory_bytes;
        if (check)
            out["exact"] = {{"pairs_checked", exact.pairs_checked}, {"true_pairs", exact.true_pairs},
                            {"false_positives", exact.false_positives.size()},
                            {"false_negatives", exact.false_negatives.size()},
                            {"skipped_degenerate", exact.skipped_degenerate}};
        std::cout << one_line(out) << "\n";
        return exit_ok;
    }
    std::printf("meshes            %s (%zu tets)", meshes[0].c_str(), a.num_tets());
    if (!self) std::printf(" x %s (%zu tets)", meshes[1].c_str(), b.num_tets());
    std::printf("%s", self ? ", self-collision" : "");
    if (rings > 0) std::printf(", exclusion rings %d", rings);
    std::printf("\n");
    std::printf("method            %s, test %s, hash %s, backend %s\n", to_string(options.method),
                to_string(options.narrow_phase), hash_label(options).c_str(), to_string(options.backend));
    if (options.margin > 0.0f) std::printf("margin            %s\n", find_option("margin")->text(options).c_str());
    std::printf("candidates        %llu (%llu to the narrow phase)\n", static_cast<unsigned long long>(c.candidates),
                static_cast<unsigned long long>(c.narrow_phase_candidates));
    // With a margin the pairs are those within it, overlapping or not; their distances split them.
    const std::uint64_t overlapping = options.distances ? overlapping_pairs(result) : 0;
    print_pair_counts(options, c.colliding_pairs, c.colliding_tets, options.distances ? &overlapping : nullptr);
    if (options.narrow_phase == NarrowPhase::exact)
        std::printf("exact stage       %llu pairs\n", static_cast<unsigned long long>(c.exact_stage_pairs));
    std::printf("times (ms)        boxes %.3f, populate %.3f, candidates %.3f, sort pairs %.3f, narrow %.3f\n",
                t.bounding_boxes, t.populate_grid, t.find_candidates, t.sort_pairs, t.narrow_phase);
    std::printf("total             %.3f ms\n", t.total);
    std::printf("memory            %zu bytes\n", result.memory_bytes);
    if (check) {
        std::printf("exact check       %zu pairs judged with CGAL, %zu intersect", exact.pairs_checked, exact.true_pairs);
        if (exact.skipped_degenerate) std::printf(" (%zu with a flat tet not judged)", exact.skipped_degenerate);
        std::printf("\n");
        print_examples("false positives", exact.false_positives);
        print_examples("false negatives", exact.false_negatives);
    }
    return exit_ok;
}

} // namespace kdet::cli
