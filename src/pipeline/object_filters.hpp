#pragma once
/// @file object_filters.hpp
/// @brief What a Detector leaves out besides disabled object pairs, kept on the host: each object's
/// collision group and mask (Detector::set_collision_filter), which it folds into the pairs of objects
/// it checks, and the pairs of tets excluded beyond shared vertices (self-exclusion rings, rest
/// contacts), which it hands the pipeline as ExclusionLists (pair_exclusions.hpp).

#include "pipeline/pair_switches.hpp"
#include "pipeline/pipeline_base.hpp"

#include <cstdint>
#include <map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace kdet {

class ObjectFilters {
public:
    /// @brief The filters of a new object (group 1, every mask bit): its row and column of the
    /// detector's switches (`pair_enabled`, already grown to the new count) follow them.
    void add_object(PairSwitches& pair_enabled);
    /// @brief Sets an object's group and mask, and with them its switches against every object whose
    /// pair with it no explicit set_pair_collision() decided.
    void set_filter(std::uint32_t object, std::uint32_t group, std::uint32_t mask, PairSwitches& pair_enabled);
    /// @brief Notes that the pair's switch was set explicitly: the filters no longer change it.
    void set_explicit(std::uint32_t a, std::uint32_t b);
    std::uint32_t group(std::uint32_t object) const { return group_[object]; }
    std::uint32_t mask(std::uint32_t object) const { return mask_[object]; }

    /// @brief An object's rings and its lists (PipelineBase::ring_exclusions(), local ids); 0 rings and no
    /// lists for none.
    void set_rings(std::uint32_t object, int rings, ExclusionLists lists);
    int rings(std::uint32_t object) const { return rings_[object]; }
    /// @brief The ids an object's ring lists hold.
    std::uint64_t ring_ids(std::uint32_t object) const { return ring_lists_[object].partners.size(); }
    /// @brief Adds pairs never to report between objects a <= b: keys (tet of a << 32) | tet of b, in
    /// ids local to each object's stored tets.
    void add_rest_pairs(std::uint32_t a, std::uint32_t b, const std::vector<std::uint64_t>& keys);
    /// @brief The rest pairs recorded between objects a <= b.
    std::size_t rest_pair_count(std::uint32_t a, std::uint32_t b) const;
    /// @brief Drops what names an object's stored tets (its ring lists and every rest pair it is in):
    /// its tets changed or it was removed. Its rings stay set.
    void forget_tets(std::uint32_t object);

    /// @brief Throws kdet::Error when `added` more ids would take the exclusions past 2^32 - 1 ids.
    void check_room(std::uint64_t added, std::uint64_t removed = 0) const;
    /// @brief Whether exclusions() changed since it was last called.
    bool exclusions_changed() const { return changed_; }
    /// @brief Every exclusion in stored ids of a pipeline whose objects' tets begin at `object_first`
    /// (PipelineBase::object_first_tets(): each object's tets together, the tet count last), each pair
    /// listed under its lower stored id only.
    ExclusionLists exclusions(const std::vector<std::uint32_t>& object_first);

private:
    std::uint64_t entries() const;

    std::vector<std::uint32_t> group_, mask_;
    std::unordered_set<std::uint64_t> explicit_pairs_; ///< (a << 32) | b, a < b
    std::vector<int> rings_;
    std::vector<ExclusionLists> ring_lists_; ///< per object, local ids; empty without rings
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint64_t>> rest_pairs_; ///< sorted keys
    bool changed_ = false;
};

} // namespace kdet
