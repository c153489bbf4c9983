#include "bench_job.hpp"

#include "bench_runner.hpp"

#include <exception>

namespace kdet::view {

cli::BenchConfig bench_config_of(const ViewSession& session, int runs, const std::string& output_dir) {
    cli::BenchConfig config;
    config.scene = session.source().meshes.empty() ? session.source().scene : session.scene().name();
    config.request = session.source().request;
    config.options = session.options();
    config.options.contacts = false;
    config.self = session.self();
    config.runs = runs;
    config.output_dir = output_dir;
    config.quiet = true;
    return config;
}

BenchJob::BenchJob(const ViewSource& source, const cli::BenchConfig& config)
    : thread_([this, source, config] { run(source, config); }) {}

BenchJob::~BenchJob() {
    stop();
    thread_.join();
}

float BenchJob::progress() const {
    const long long total = frames_total_.load();
    return total > 0 ? static_cast<float>(frames_done_.load()) / static_cast<float>(total) : 0.0f;
}

std::string BenchJob::outcome() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return outcome_;
}

bool BenchJob::succeeded() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return succeeded_;
}

cli::BenchFiles BenchJob::files() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return files_;
}

void BenchJob::run(const ViewSource& source, const cli::BenchConfig& config) {
    std::string outcome;
    bool succeeded = false;
    cli::BenchFiles files;
    try {
        const std::unique_ptr<Scene> scene = open_view_source(source);
        const int frames = cli::last_frame_of(config, *scene) - config.first_frame + 1;
        frames_total_.store(static_cast<long long>(frames) * config.runs);
        const cli::BenchOutcome result = cli::run_benchmark(config, *scene, [&](int run, int frame_index) {
            frames_done_.store(static_cast<long long>(run) * frames + frame_index);
            return !stop_requested_.load();
        });
        if (result.stopped) {
            outcome = "stopped; no files written";
        } else {
            frames_done_.store(frames_total_.load());
            files = cli::write_bench_files(config.output_dir, result.stem, result.header, result.runs);
            outcome = "wrote " + files.averages + " and " + files.runs;
            succeeded = true;
        }
    } catch (const std::exception& e) {
        outcome = std::string("benchmark failed: ") + e.what();
    }
    {
        std::lock_guard<std::mutex> lock(mutex_);
        outcome_ = outcome;
        succeeded_ = succeeded;
        files_ = files;
    }
    finished_.store(true);
}

} // namespace kdet::view
