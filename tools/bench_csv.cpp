#include "bench_csv.hpp"

#include <kdet/error.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <ostream>

namespace kdet::cli {

namespace {

std::size_t flagged(const FrameResult& result, std::size_t object) {
    if (object >= result.colliding.size()) return 0;
    const auto& flags = result.colliding[object];
    return static_cast<std::size_t>(std::count_if(flags.begin(), flags.end(), [](std::uint8_t f) { return f != 0; }));
}

std::string format_value(double value) {
    char text[64];
    // Counts stay exact as doubles up to 2^53, far beyond any count here.
    if (value == std::floor(value) && std::fabs(value) < 1e15)
        std::snprintf(text, sizeof text, "%.0f", value);
    else
        std::snprintf(text, sizeof text, "%.6f", value);
    return text;
}

void write_file(const std::string& path, const std::vector<HeaderField>& header, const std::vector<std::string>& columns,
                const std::vector<FrameRow>& rows) {
    std::ofstream out(path);
    if (!out) throw Error(path + ": cannot open file for writing");
    write_bench_csv(out, header, columns, rows);
    out.flush();
    if (!out) throw Error(path + ": write failed");
}

} // namespace

const std::vector<std::string>& frame_columns() {
    static const std::vector<std::string> columns = {
        "frame", "host time", "device time", "bbox time", "collision time", "col tets A to B", "col tets B to A",
        "collision pairs", "populate time", "find candidates time", "sort unique time", "narrow phase time",
        "candidates", "unique candidates", "colliding tets", "buffer regrows", "memory bytes", "bbox overlap x",
        "exact stage pairs"};
    return columns;
}

FrameRow make_frame_row(int frame, double host_ms, const FrameResult& result, double overlap_x) {
    const StageTimes& t = result.times;
    const FrameCounts& c = result.counts;
    return {static_cast<double>(frame),
            host_ms,
            t.total,
            t.bounding_boxes,
            t.populate_grid + t.find_candidates + t.sort_pairs + t.narrow_phase,
            static_cast<double>(flagged(result, 0)),
            static_cast<double>(flagged(result, 1)),
            static_cast<double>(c.colliding_pairs),
            t.populate_grid,
            t.find_candidates,
            t.sort_pairs,
            t.narrow_phase,
            static_cast<double>(c.candidates),
            static_cast<double>(c.narrow_phase_candidates),
            static_cast<double>(c.colliding_tets),
            static_cast<double>(c.buffer_regrows),
            static_cast<double>(result.memory_bytes),
            overlap_x,
            static_cast<double>(c.exact_stage_pairs)};
}

double box_overlap_x(const std::vector<float>& a, const std::vector<float>& b) {
    const auto x_range = [](const std::vector<float>& xyz) {
        float lo = std::numeric_limits<float>::infinity(), hi = -lo;
        for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) {
            lo = std::min(lo, xyz[i]);
            hi = std::max(hi, xyz[i]);
        }
        return std::pair{lo, hi};
    };
    const auto [lo_a, hi_a] = x_range(a);
    const auto [lo_b, hi_b] = x_range(b);
    return static_cast<double>(std::min(hi_a, hi_b)) - static_cast<double>(std::max(lo_a, lo_b));
}

std::vector<FrameRow> average_runs(const std::vector<std::vector<FrameRow>>& runs) {
    if (runs.empty()) return {};
    std::vector<FrameRow> mean(runs[0].size());
    for (std::size_t f = 0; f < mean.size(); ++f) {
        mean[f].assign(runs[0][f].size(), 0.0);
        for (const auto& run : runs)
            for (std::size_t c = 0; c < mean[f].size(); ++c) mean[f][c] += run.at(f).at(c);
        for (double& value : mean[f]) value /= static_cast<double>(runs.size());
    }
    return mean;
}

std::vector<FrameRow> rows_with_run(const std::vector<std::vector<FrameRow>>& runs) {
    std::vector<FrameRow> rows;
    for (std::size_t r = 0; r < runs.size(); ++r)
        for (const FrameRow& row : runs[r]) {
            rows.push_back({static_cast<double>(r)});
            rows.back().insert(rows.back().end(), row.begin(), row.end());
        }
    return rows;
}

void write_bench_csv(std::ostream& out, const std::vector<HeaderField>& header, const std::vector<std::string>& columns,
                     const std::vector<FrameRow>& rows) {
    for (const auto& [key, value] : header) out << key << ", " << value << '\n';
    for (std::size_t c = 0; c < columns.size(); ++c) out << (c ? ", " : "") << columns[c];
    out << '\n';
    for (const FrameRow& row : rows) {
        for (std::size_t c = 0; c < row.size(); ++c) out << (c ? ", " : "") << format_value(row[c]);
        out << '\n';
    }
}

BenchFiles write_bench_files(const std::string& dir, const std::string& stem, const std::vector<HeaderField>& header,
                             const std::vector<std::vector<FrameRow>>& runs) {
    std::error_code error;
    std::filesystem::create_directories(dir, error);
    if (error) throw Error(dir + ": cannot create folder (" + error.message() + ")");
    const std::filesystem::path base = std::filesystem::path(dir) / stem;
    BenchFiles files{base.string() + ".csv", base.string() + "_runs.csv"};
    std::vector<std::string> raw_columns = {"run"};
    raw_columns.insert(raw_columns.end(), frame_columns().begin(), frame_columns().end());
    write_file(files.averages, header, frame_columns(), average_runs(runs));
    write_file(files.runs, header, raw_columns, rows_with_run(runs));
    return files;
}

} // namespace kdet::cli
