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

} // namespace

void ObjectFilters::add_object(PairSwitches& pair_enabled) {
    group_.push_back(1);
    mask_.push_back(~0u);
    rings_.push_back(0);
    ring_lists_.emplace_back();
    const auto object = static_cast<std::uint32_t>(group_.size() - 1);
    set_filter(object, group_[object], mask_[object], pair_enabled);
}

void ObjectFilters::set_filter(std::uint32_t object, std::uint32_t group, std::uint32_t mask,
                               PairSwitches& pair_enabled) {
    group_[object] = group;
    mask_[object] = mask;
    const std::size_t n = group_.size();
    for (std::uint32_t other = 0; other < n; ++other) {
        if (other == object) continue;
        const std::uint64_t key = object < other ? (std::uint64_t{object} << 32 | other) : (std::uint64_t{other} << 32 | object);
        if (explicit_pairs_.count(key)) continue;
        const std::uint8_t on = (group_[object] & mask_[other]) != 0 && (group_[other] & mask_[object]) != 0;
        pair_enabled(object, other) = pair_enabled(other, object) = on;
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
    for (const auto& pairs : rest_pairs_) ids += pairs.second.size();
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
    // Per tet: its ring partners (later tets of its object, whose stored tets keep their order), then
    // the rest partners of which it is the lower tet, which may repeat a ring partner and come in no
    // order; each tet's list is sorted and made unique afterwards.
    const auto lower = [&](const std::pair<std::uint32_t, std::uint32_t>& objects, std::uint64_t key) {
        const std::uint32_t t = object_first[objects.first] + static_cast<std::uint32_t>(key >> 32);
        const std::uint32_t u = object_first[objects.second] + static_cast<std::uint32_t>(key);
        return t < u ? std::make_pair(t, u) : std::make_pair(u, t);
    };
    std::vector<std::uint32_t> count(std::size_t{tets} + 1, 0);
    for (std::size_t o = 0; o < ring_lists_.size(); ++o) {
        const std::vector<std::uint32_t>& begin = ring_lists_[o].begin;
        for (std::size_t t = 0; t + 1 < begin.size(); ++t) count[object_first[o] + t + 1] += begin[t + 1] - begin[t];
    }
    for (const auto& [objects, keys] : rest_pairs_)
        for (const std::uint64_t key : keys) ++count[lower(objects, key).first + 1];
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
            const auto [t, u] = lower(objects, key);
            partners[cursor[t]++] = u;
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
