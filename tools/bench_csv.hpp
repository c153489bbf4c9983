#pragma once
/// @file bench_csv.hpp
/// @brief Benchmark files in the thesis's format (appendix A.1.4): `key, value` header lines, a
/// column line, then one row per frame, all separated by ", ".

#include <kdet/results.hpp>

#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

namespace kdet::cli {

/// @brief One `key, value` header line; the value is everything after the first ", ".
using HeaderField = std::pair<std::string, std::string>;

/// @brief The values of one frame, in frame_columns() order.
using FrameRow = std::vector<double>;

/// @brief The per-frame columns: the thesis's eight (frame, host time, device time, bbox time,
/// collision time, col tets A to B, col tets B to A, collision pairs), then per-stage times,
/// candidate counts, memory, the box overlap along x and the pairs that reached the exact stage of
/// the `exact` test.
const std::vector<std::string>& frame_columns();

/// @brief One frame's row. `host_ms` is the wall-clock time around detect(), `overlap_x` the
/// value of box_overlap_x for this frame. "col tets A to B" counts the flagged tets of object 0,
/// "B to A" those of object 1; "collision time" is the sum of the stages after the box check.
FrameRow make_frame_row(int frame, double host_ms, const FrameResult& result, double overlap_x);

/// @brief Extent along x of the intersection of the bounding boxes of two point sets (x y z each);
/// negative when the boxes are apart along x. The thesis's measure of penetration depth (6.3.1).
double box_overlap_x(const std::vector<float>& a, const std::vector<float>& b);

/// @brief Per-frame mean of every column over the runs; `runs[r][f]` is frame f of run r, and
/// every run must hold the same frames.
std::vector<FrameRow> average_runs(const std::vector<std::vector<FrameRow>>& runs);

/// @brief The rows of every run, each preceded by its 0-based run index (the "run" column).
std::vector<FrameRow> rows_with_run(const std::vector<std::vector<FrameRow>>& runs);

/// @brief Writes the header lines, the column line and the rows. Whole numbers are written without
/// decimals, others with 6 decimals.
void write_bench_csv(std::ostream& out, const std::vector<HeaderField>& header,
                     const std::vector<std::string>& columns, const std::vector<FrameRow>& rows);

/// @brief Paths of the two files of one benchmark.
struct BenchFiles {
    std::string averages; ///< `dir/stem.csv`: per-frame averages over the runs
    std::string runs;     ///< `dir/stem_runs.csv`: every run, with a leading "run" column
};

/// @brief Creates `dir` when needed and writes both files. Throws kdet::Error when a file cannot
/// be written.
BenchFiles write_bench_files(const std::string& dir, const std::string& stem, const std::vector<HeaderField>& header,
                             const std::vector<std::vector<FrameRow>>& runs);

} // namespace kdet::cli
