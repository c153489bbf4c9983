#pragma once
/// @file bench_progress.hpp
/// @brief A one-line progress bar (run and frame) on stderr, drawn only when stderr is a terminal.

#include <chrono>

namespace kdet::cli {

/// @brief Redraws at most ten times a second so that fast frames are not slowed by terminal output.
class ProgressBar {
public:
    /// @brief `enabled` false (or stderr not a terminal) makes every call a no-op.
    ProgressBar(bool enabled, int runs, int frames);
    ~ProgressBar();
    ProgressBar(const ProgressBar&) = delete;
    ProgressBar& operator=(const ProgressBar&) = delete;

    /// @brief Reports that frame `frame_index` (0-based within the range) of run `run` is next.
    void update(int run, int frame_index);
    /// @brief Erases the bar; called by the destructor too.
    void finish();

private:
    void draw(int run, int frame_index);

    bool active_;
    int runs_, frames_;
    std::chrono::steady_clock::time_point last_draw_{};
};

} // namespace kdet::cli
