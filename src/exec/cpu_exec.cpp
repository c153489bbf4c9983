#include "exec/cpu_exec.hpp"

#include <omp.h>

#include <algorithm>
#include <fstream>
#include <parallel/algorithm>
#include <vector>

namespace kdet {

CpuExec::CpuExec(const DetectorOptions& options)
    : threads_(options.threads > 0 ? options.threads : omp_get_max_threads()) {}

void CpuExec::sort(std::uint64_t* keys, std::size_t n, int) const {
    if (n > 1 << 14 && threads_ > 1)
        __gnu_parallel::sort(keys, keys + n, __gnu_parallel::multiway_mergesort_tag(static_cast<__gnu_parallel::_ThreadIndex>(threads_)));
    else
        std::sort(keys, keys + n);
}

std::uint64_t CpuExec::exclusive_scan(const std::uint32_t* in, std::uint32_t* out, std::size_t n) const {
    if (n == 0) return 0;
    ++host_waits_;
    // Two passes over per-thread blocks: block sums, then each block scans from its offset.
    const int blocks = std::max(1, std::min<int>(threads_, static_cast<int>(n / 4096)));
    std::vector<std::uint64_t> block_sum(static_cast<std::size_t>(blocks) + 1, 0);
    const std::size_t per_block = (n + blocks - 1) / blocks;
#pragma omp parallel for num_threads(blocks)
    for (int b = 0; b < blocks; ++b) {
        const std::size_t lo = std::min(n, b * per_block), hi = std::min(n, lo + per_block);
        std::uint64_t sum = 0;
        for (std::size_t i = lo; i < hi; ++i) sum += in[i];
        block_sum[static_cast<std::size_t>(b) + 1] = sum;
    }
    for (int b = 0; b < blocks; ++b) block_sum[b + 1] += block_sum[b];
#pragma omp parallel for num_threads(blocks)
    for (int b = 0; b < blocks; ++b) {
        const std::size_t lo = std::min(n, b * per_block), hi = std::min(n, lo + per_block);
        std::uint64_t running = block_sum[b];
        for (std::size_t i = lo; i < hi; ++i) {
            const std::uint32_t value = in[i];
            out[i] = static_cast<std::uint32_t>(running);
            running += value;
        }
    }
    return block_sum[blocks];
}

std::string CpuExec::device_name() const {
    std::ifstream cpuinfo("/proc/cpuinfo");
    std::string line;
    while (std::getline(cpuinfo, line))
        if (line.rfind("model name", 0) == 0) {
            const auto colon = line.find(':');
            if (colon != std::string::npos) return line.substr(std::min(line.size(), colon + 2));
        }
    return "unknown CPU";
}

} // namespace kdet
