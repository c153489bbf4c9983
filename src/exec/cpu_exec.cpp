#include "exec/cpu_exec.hpp"
#include "exec/radix_sort.hpp"

#include <omp.h>

#include <algorithm>
#include <fstream>
#include <vector>

namespace kdet {

CpuExec::CpuExec(const DetectorOptions& options)
    : threads_(options.threads > 0 ? options.threads : omp_get_max_threads()) {}

void CpuExec::sort(std::uint64_t* keys, std::size_t capacity, const unsigned long long* count, int bits) const {
    const std::size_t n = std::min<std::size_t>(capacity, *count);
    if (sort_scratch_.size() < n) sort_scratch_.resize_discard(n);
    radix_sort(keys, n, bits, sort_scratch_.data(), threads_);
}

void CpuExec::sum(const std::uint32_t* in, std::size_t n, unsigned long long* total) const {
    unsigned long long s = 0;
    const auto count = static_cast<std::int64_t>(n);
#pragma omp parallel for reduction(+ : s) num_threads(threads_) if (count > 4096)
    for (std::int64_t i = 0; i < count; ++i) s += in[i];
    *total = s;
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
