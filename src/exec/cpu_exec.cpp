#include "exec/cpu_exec.hpp"

#include <omp.h>

#include <algorithm>
#include <fstream>
#include <utility>
#include <vector>

namespace kdet {

CpuExec::CpuExec(const DetectorOptions& options)
    : threads_(options.threads > 0 ? options.threads : omp_get_max_threads()) {}

void radix_sort(std::uint64_t* keys, std::size_t n, int bits, std::uint64_t* scratch) {
    if (n <= 1 << 14) {
        std::sort(keys, keys + n);
        return;
    }
    // Only over the bits the keys use, skipping digits that every key shares (a pair key of a 100k-tet
    // mesh: 4 passes where a comparison sort makes log2(n) of them).
    constexpr int digit_bits = 11;
    constexpr std::size_t digits = std::size_t{1} << digit_bits;
    std::vector<std::size_t> start(digits);
    std::uint64_t* from = keys;
    std::uint64_t* to = scratch;
    for (int shift = 0; shift < bits; shift += digit_bits) {
        std::fill(start.begin(), start.end(), std::size_t{0});
        for (std::size_t i = 0; i < n; ++i) ++start[(from[i] >> shift) & (digits - 1)];
        if (std::find(start.begin(), start.end(), n) != start.end()) continue; // one digit: nothing moves
        std::size_t sum = 0;
        for (std::size_t& s : start) sum += std::exchange(s, sum);
        for (std::size_t i = 0; i < n; ++i) to[start[(from[i] >> shift) & (digits - 1)]++] = from[i];
        std::swap(from, to);
    }
    if (from != keys) std::copy(from, from + n, keys);
}

void CpuExec::sort(std::uint64_t* keys, std::size_t capacity, const unsigned long long* count, int bits) const {
    const std::size_t n = std::min<std::size_t>(capacity, *count);
    if (n > 1 << 14 && sort_scratch_.size() < n) sort_scratch_.resize_discard(n);
    radix_sort(keys, n, bits, sort_scratch_.data());
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
