#pragma once
/// @file bench_job.hpp
/// @brief The viewer's benchmark button: `kdet bench` on a thread of its own, with the same runner
/// and the same CSV files, so that the window stays responsive and shows its progress.

#include "bench_args.hpp"
#include "bench_csv.hpp"
#include "session.hpp"

#include <atomic>
#include <mutex>
#include <string>
#include <thread>

namespace kdet::view {

/// @brief The `kdet bench` settings that repeat what @p session shows: its scene, detector options
/// (contacts off, as `kdet bench` runs), self-collision, every frame; @p runs runs into @p output_dir.
cli::BenchConfig bench_config_of(const ViewSession& session, int runs, const std::string& output_dir);

/// @brief Runs one benchmark in the background. It opens its own copy of the scene, so the viewer's
/// scene and detector are never shared with it.
class BenchJob {
public:
    BenchJob(const ViewSource& source, const cli::BenchConfig& config);
    /// @brief Stops the benchmark if it still runs, and waits for it.
    ~BenchJob();
    BenchJob(const BenchJob&) = delete;
    BenchJob& operator=(const BenchJob&) = delete;

    /// @brief Fraction of the frames done, 0 to 1.
    float progress() const;
    bool finished() const { return finished_.load(); }
    /// @brief Asks the benchmark to stop before its next frame; no files are written then.
    void stop() { stop_requested_.store(true); }

    /// @brief After finished(): what happened, as one line ("wrote DIR/STEM.csv and ...", "stopped",
    /// or the error), and whether the files were written.
    std::string outcome() const;
    bool succeeded() const;
    /// @brief After a success: the two files written.
    cli::BenchFiles files() const;

private:
    void run(const ViewSource& source, const cli::BenchConfig& config);

    std::atomic<long long> frames_done_{0}, frames_total_{0};
    std::atomic<bool> stop_requested_{false}, finished_{false};
    mutable std::mutex mutex_; ///< guards the fields below, written once by the job's thread
    std::string outcome_;
    bool succeeded_ = false;
    cli::BenchFiles files_;
    std::thread thread_;
};

} // namespace kdet::view
