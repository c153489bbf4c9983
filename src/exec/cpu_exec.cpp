#include "exec/cpu_exec.hpp"
#include "exec/radix_sort.hpp"

#include <omp.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <vector>

namespace kdet {

CpuExec::CpuExec(const DetectorOptions& options)
    : threads_(options.threads > 0 ? options.threads : omp_get_max_threads()) {}

void CpuExec::sort(std::uint64_t* keys, std::size_t capacity, const unsigned long long* count, int bits, int low_word_bits) const {
    const std::size_t n = std::min<std::size_t>(capacity, *count);
    if (sort_scratch_.size() < n) sort_scratch_.resize_discard(n);
    radix_sort(keys, n, bits, sort_scratch_.data(), threads_, 0, low_word_bits);
}

void CpuExec::sort_by_high_word(std::uint64_t* keys, std::size_t capacity, const unsigned long long* count, int bits) const {
    const std::size_t n = std::min<std::size_t>(capacity, *count);
    if (sort_scratch_.size() < n) sort_scratch_.resize_discard(n);
    radix_sort(keys, n, bits, sort_scratch_.data(), threads_, 32);
}

void CpuExec::sort_lists(const std::uint32_t* keys, std::uint32_t* sorted, std::size_t, const std::uint32_t* begin,
                         const std::uint32_t* end, std::size_t lists) const {
    // Ciura's gaps, then times 2.25; only those below half the list are used.
    constexpr std::uint32_t gaps[] = {1u, 4u, 10u, 23u, 57u, 132u, 301u, 701u, 1577u, 3548u, 7983u, 17961u,
                                      40412u, 90927u, 204585u, 460316u, 1035711u, 2330349u, 5243285u};
    for_each(lists, [&](std::uint64_t list) {
        const std::uint32_t first = begin[list], n = end[list] - first;
        std::uint32_t* out = sorted + first;
        std::copy(keys + first, keys + first + n, out);
        // The CPU's threads populate in about id order, so most lists arrive sorted: one look, no passes.
        if (std::is_sorted(out, out + n)) return;
        int largest = 0;
        while (largest + 1 < static_cast<int>(std::size(gaps)) && 2u * gaps[largest + 1] < n) ++largest;
        for (int pass = largest; pass >= 0; --pass) {
            const std::uint32_t gap = gaps[pass];
            for (std::uint32_t i = gap; i < n; ++i) {
                const std::uint32_t key = out[i];
                std::uint32_t j = i;
                for (; j >= gap && out[j - gap] > key; j -= gap) out[j] = out[j - gap];
                out[j] = key;
            }
        }
    });
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
