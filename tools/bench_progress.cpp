#include "bench_progress.hpp"

#include <unistd.h>

#include <cstdio>
#include <string>

namespace kdet::cli {

namespace {

constexpr int bar_width = 30;

} // namespace

ProgressBar::ProgressBar(bool enabled, int runs, int frames)
    : active_(enabled && isatty(STDERR_FILENO) != 0), runs_(runs), frames_(frames) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(int run, int frame_index) {
    if (!active_) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_draw_ < std::chrono::milliseconds(100)) return;
    last_draw_ = now;
    draw(run, frame_index);
}

void ProgressBar::draw(int run, int frame_index) {
    const long long done = static_cast<long long>(run) * frames_ + frame_index;
    const long long total = static_cast<long long>(runs_) * frames_;
    const int filled = total > 0 ? static_cast<int>(done * bar_width / total) : bar_width;
    const std::string bar = std::string(static_cast<std::size_t>(filled), '#') +
                            std::string(static_cast<std::size_t>(bar_width - filled), '.');
    std::fprintf(stderr, "\r[%s] run %d/%d, frame %d/%d ", bar.c_str(), run + 1, runs_, frame_index + 1, frames_);
    std::fflush(stderr);
}

void ProgressBar::finish() {
    if (!active_) return;
    // Overwrite the bar with blanks so that the next output starts on a clean line.
    std::fprintf(stderr, "\r%*s\r", bar_width + 48, "");
    std::fflush(stderr);
    active_ = false;
}

} // namespace kdet::cli
