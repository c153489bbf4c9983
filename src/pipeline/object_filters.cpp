#include "pipeline/object_filters.hpp"

#include <kdet/error.hpp>

#include <algorithm>
#include <string>

namespace kdet {

namespace {

constexpr std::uint64_t max_exclusion_ids = 0xffffffffull;

std::string too_many_ids(std::uint64_t ids) {
    return "exclusions would hold " + std::to_string(ids) + " tet ids, more than " + std::to_string(max_exclusion_ids);
}

/// One thread's marks for the rings around one tet at a time: a vertex or tet is marked for tet t
/// when its stamp is t + 1, so nothing is cleared between tets.
struct RingScratch {
    std::vector<std::uint32_t> vertex_stamp, tet_stamp, frontier, next;
    RingScratch(std::uint32_t vertices, std::uint32_t tets) : vertex_stamp(vertices, 0), tet_stamp(tets, 0) {}
};

/// The tets around tet t as ring_exclusions() defines them, sorted, into `out`.
void ring_partners(const TetIndices* tets, std::uint32_t first_vertex, const std::vector<std::uint32_t>& vertex_begin,
                   const std::vector<std::uint32_t>& vertex_tets, int rings, std::uint32_t t, RingScratch& s,
                   std::vector<std::uint32_t>& out) {
    const std::uint32_t stamp = t + 1;
    out.clear();
    s.frontier.clear();
    for (std::uint32_t v : tets[t].v) {
        v -= first_vertex;
        if (s.vertex_stamp[v] != stamp) s.vertex_stamp[v] = stamp, s.frontier.push_back(v);
    }
    // Tets sharing a vertex with t are left out already: marked, not listed.
    for (std::uint32_t v : s.frontier)
        for (std::uint32_t i = vertex_begin[v]; i < vertex_begin[v + 1]; ++i) s.tet_stamp[vertex_tets[i]] = stamp;
    for (int ring = 0; ring < rings; ++ring) {
        s.next.clear();
        for (std::uint32_t v : s.frontier)
            for (std::uint32_t i = vertex_begin[v]; i < vertex_begin[v + 1]; ++i)
                for (std::uint32_t x : tets[vertex_tets[i]].v) {
                    x -= first_vertex;
                    if (s.vertex_stamp[x] != stamp) s.vertex_stamp[x] = stamp, s.next.push_back(x);
                }
        for (std::uint32_t v : s.next)
            for (std::uint32_t i = vertex_begin[v]; i < vertex_begin[v + 1]; ++i) {
                const std::uint32_t u = vertex_tets[i];
                if (s.tet_stamp[u] != stamp) s.tet_stamp[u] = stamp, out.push_back(u);
            }
        s.frontier.swap(s.next);
    }
    std::sort(out.begin(), out.end());
}

} // namespace

ExclusionLists ring_exclusions(const TetIndices* tets, std::uint32_t tet_count, std::uint32_t first_vertex,
                               std::uint32_t vertex_count, int rings, std::uint32_t object, int threads) {
    // Each vertex's tets, as a compressed row array.
    std::vector<std::uint32_t> vertex_begin(std::size_t{vertex_count} + 1, 0), vertex_tets(4 * std::size_t{tet_count});
    for (std::uint32_t t = 0; t < tet_count; ++t)
        for (std::uint32_t v : tets[t].v) ++vertex_begin[v - first_vertex + 1];
    for (std::uint32_t v = 0; v < vertex_count; ++v) vertex_begin[v + 1] += vertex_begin[v];
    {
        std::vector<std::uint32_t> cursor(vertex_begin.begin(), vertex_begin.end() - 1);
        for (std::uint32_t t = 0; t < tet_count; ++t)
            for (std::uint32_t v : tets[t].v) vertex_tets[cursor[v - first_vertex]++] = t;
    }
    // Two passes over the tets, each list found on its own: one counts, one writes in place.
    ExclusionLists lists;
    lists.begin.assign(std::size_t{tet_count} + 1, 0);
    const auto n = static_cast<std::ptrdiff_t>(tet_count);
    for (int pass = 0; pass < 2; ++pass) {
#pragma omp parallel num_threads(threads)
        {
            RingScratch scratch(vertex_count, tet_count);
            std::vector<std::uint32_t> found;
#pragma omp for schedule(dynamic, 64)
            for (std::ptrdiff_t i = 0; i < n; ++i) {
                const auto t = static_cast<std::uint32_t>(i);
                ring_partners(tets, first_vertex, vertex_begin, vertex_tets, rings, t, scratch, found);
                if (pass == 0)
                    lists.begin[t + 1] = static_cast<std::uint32_t>(found.size());
                else
                    std::copy(found.begin(), found.end(), lists.partners.begin() + lists.begin[t]);
            }
        }
        if (pass == 1) break;
        std::uint64_t total = 0;
        for (std::uint32_t t = 0; t < tet_count; ++t) {
            total += lists.begin[t + 1];
            if (total > max_exclusion_ids)
                throw Error("object " + std::to_string(object) + ": " + std::to_string(rings) + " exclusion rings: " +
                            too_many_ids(total));
            lists.begin[t + 1] = static_cast<std::uint32_t>(total);
        }
        lists.partners.resize(total);
    }
    return lists;
}

void ObjectFilters::add_object(std::vector<std::uint8_t>& pair_enabled) {
    group_.push_back(1);
    mask_.push_back(~0u);
    rings_.push_back(0);
    ring_lists_.emplace_back();
    const auto object = static_cast<std::uint32_t>(group_.size() - 1);
    set_filter(object, group_[object], mask_[object], pair_enabled);
}

void ObjectFilters::set_filter(std::uint32_t object, std::uint32_t group, std::uint32_t mask,
                               std::vector<std::uint8_t>& pair_enabled) {
    group_[object] = group;
    mask_[object] = mask;
    const std::size_t n = group_.size();
    for (std::uint32_t other = 0; other < n; ++other) {
        if (other == object) continue;
        const std::uint64_t key = object < other ? (std::uint64_t{object} << 32 | other) : (std::uint64_t{other} << 32 | object);
        if (explicit_pairs_.count(key)) continue;
        const std::uint8_t on = (group_[object] & mask_[other]) != 0 && (group_[other] & mask_[object]) != 0;
        pair_enabled[object * n + other] = pair_enabled[other * n + object] = on;
    }
}

void ObjectFilters::set_explicit(std::uint32_t a, std::uint32_t b) {
    explicit_pairs_.insert(a < b ? (std::uint64_t{a} << 32 | b) : (std::uint64_t{b} << 32 | a));
}

void ObjectFilters::set_rings(std::uint32_t object, int rings, ExclusionLists lists) {
    rings_[object] = rings;
    ring_lists_[object] = std::move(lists);
    changed_ = true;
}

void ObjectFilters::add_rest_pairs(std::uint32_t a, std::uint32_t b, const std::vector<std::uint64_t>& keys) {
    if (keys.empty()) return;
    std::vector<std::uint64_t>& held = rest_pairs_[{a, b}];
    std::vector<std::uint64_t> merged;
    merged.reserve(held.size() + keys.size());
    std::set_union(held.begin(), held.end(), keys.begin(), keys.end(), std::back_inserter(merged));
    held.swap(merged);
    changed_ = true;
}

std::size_t ObjectFilters::rest_pair_count(std::uint32_t a, std::uint32_t b) const {
    const auto found = rest_pairs_.find({a, b});
    return found == rest_pairs_.end() ? 0 : found->second.size();
}

void ObjectFilters::forget_tets(std::uint32_t object) {
    changed_ = changed_ || !ring_lists_[object].partners.empty();
    ring_lists_[object] = ExclusionLists{};
    for (auto it = rest_pairs_.begin(); it != rest_pairs_.end();) {
        if (it->first.first == object || it->first.second == object) {
            it = rest_pairs_.erase(it);
            changed_ = true;
        } else {
            ++it;
        }
    }
}

std::uint64_t ObjectFilters::entries() const {
    std::uint64_t ids = 0;
    for (const ExclusionLists& lists : ring_lists_) ids += lists.partners.size();
    for (const auto& pairs : rest_pairs_) ids += 2 * pairs.second.size();
    return ids;
}

void ObjectFilters::check_room(std::uint64_t added, std::uint64_t removed) const {
    const std::uint64_t ids = entries() - removed + added;
    if (ids > max_exclusion_ids) throw Error(too_many_ids(ids));
}

ExclusionLists ObjectFilters::exclusions(const std::vector<std::uint32_t>& object_first) {
    changed_ = false;
    ExclusionLists out;
    if (entries() == 0) return out;
    const std::uint32_t tets = object_first.back();
    // Per tet: its ring partners, then its rest partners (in either role), which may repeat a ring
    // partner and come in no order; each tet's list is sorted and made unique afterwards.
    std::vector<std::uint32_t> count(std::size_t{tets} + 1, 0);
    for (std::size_t o = 0; o < ring_lists_.size(); ++o) {
        const std::vector<std::uint32_t>& begin = ring_lists_[o].begin;
        for (std::size_t t = 0; t + 1 < begin.size(); ++t) count[object_first[o] + t + 1] += begin[t + 1] - begin[t];
    }
    for (const auto& [objects, keys] : rest_pairs_)
        for (const std::uint64_t key : keys) {
            ++count[object_first[objects.first] + static_cast<std::uint32_t>(key >> 32) + 1];
            ++count[object_first[objects.second] + static_cast<std::uint32_t>(key) + 1];
        }
    for (std::uint32_t t = 0; t < tets; ++t) count[t + 1] += count[t];
    std::vector<std::uint32_t> partners(count[tets]), cursor(count.begin(), count.end() - 1);
    for (std::size_t o = 0; o < ring_lists_.size(); ++o) {
        const ExclusionLists& lists = ring_lists_[o];
        const std::uint32_t first = object_first[o];
        for (std::size_t t = 0; t + 1 < lists.begin.size(); ++t)
            for (std::uint32_t i = lists.begin[t]; i < lists.begin[t + 1]; ++i)
                partners[cursor[first + t]++] = first + lists.partners[i];
    }
    for (const auto& [objects, keys] : rest_pairs_)
        for (const std::uint64_t key : keys) {
            const std::uint32_t t = object_first[objects.first] + static_cast<std::uint32_t>(key >> 32);
            const std::uint32_t u = object_first[objects.second] + static_cast<std::uint32_t>(key);
            partners[cursor[t]++] = u;
            partners[cursor[u]++] = t;
        }
    out.begin.assign(std::size_t{tets} + 1, 0);
    out.partners.reserve(partners.size());
    for (std::uint32_t t = 0; t < tets; ++t) {
        const auto first = partners.begin() + count[t], last = partners.begin() + count[t + 1];
        std::sort(first, last);
        out.partners.insert(out.partners.end(), first, std::unique(first, last));
        out.begin[t + 1] = static_cast<std::uint32_t>(out.partners.size());
    }
    return out;
}

} // namespace kdet
