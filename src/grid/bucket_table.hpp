#pragma once
/// @file bucket_table.hpp
/// @brief The hash table that stores the grid: fixed-capacity buckets, rehash probing on misses,
/// overflow buckets chained per cell, and a frame stamp so the table never needs clearing. Once
/// filled, each cell's chain is copied into one contiguous list of entries sorted by id
/// (gather_cell, a sort, place_entry), which is what queries read.
///
/// A bucket's `state` is stamp*2 while a thread is writing its header and stamp*2+1 once it is ready;
/// any other stamp means the bucket is empty this frame. Overflow buckets come from a pool after the
/// main slots. When probing or the pool runs out, the insert reports it and the host grows and reruns.

#include "exec/atomic.hpp"
#include "geometry/vec3.hpp"
#include "grid/grid_math.hpp"

#include <cstdint>

namespace kdet {

constexpr std::uint32_t no_bucket = 0xffffffffu;

/// @brief The automatic bucket capacity: four times the mean ids per occupied cell, from a plan's count
/// of entries and its bound on the occupied cells (so never above the true mean), rounded up to a power
/// of two and kept within [4, 32]. Most cells then fit in their main bucket: each further bucket of a
/// chain costs every later insert into the cell one more atomic add. A larger bucket only makes every
/// slot of a sparse table carry unused room.
inline std::uint32_t automatic_bucket_capacity(double entries, double occupied_cells) {
    std::uint32_t capacity = 4;
    while (capacity < 32 && capacity * occupied_cells < 4.0 * entries) capacity *= 2;
    return capacity;
}

/// @brief Bits of GridView::failure.
enum GridFailure : std::uint32_t { grid_table_full = 1u, grid_overflow_pool_full = 2u, grid_entries_full = 4u };

struct BucketHeader {
    std::uint32_t state;
    /// Ids appended so far (may exceed the capacity: the chain holds the rest). Once the cell is
    /// compacted, on its main bucket: the cell's entries, all of its chain.
    std::uint32_t count;
    std::uint32_t next;        ///< overflow bucket for the same cell, or no_bucket
    std::uint32_t first_entry; ///< once compacted, on the main bucket: where the cell's entries start
    /// Once compacted, on the main bucket: the objects its entries belong to, bit (object mod 32)
    /// (object_bit), so that a query checked against none of them skips the cell unread.
    std::uint32_t objects;
    /// On the main bucket while populating: the last bucket chained to it so far (itself at first),
    /// where inserts start instead of walking the chain's full buckets.
    std::uint32_t tail;
    std::uint64_t key;
};
static_assert(sizeof(BucketHeader) == 32, "a table slot takes 32 bytes");

/// @brief An object's bit in BucketHeader::objects and in the query's mask of objects it is checked
/// against; objects 32 apart share a bit, which only costs a cell read for nothing.
KDET_HD inline std::uint32_t object_bit(std::uint32_t object) { return 1u << (object & 31u); }

/// @brief The mask of a query that is checked against every object.
constexpr std::uint32_t any_object = ~0u;

/// @brief The object bits (object_bit) of objects 0 to count - 1 together.
KDET_HD inline std::uint32_t all_object_bits(std::uint32_t count) { return count >= 32u ? any_object : (1u << count) - 1u; }

/// @brief Bits of an id as the buckets and lists store it; above them, the axes along which the id's
/// box starts in the cell (bit a: its first cell along axis a is this one), which decides the cell
/// a pair is reported from. Tet ids stay below 2^grid_id_bits (Detector checks).
constexpr int grid_id_bits = 29;
constexpr std::uint32_t grid_id_mask = (1u << grid_id_bits) - 1u;

/// @brief An id with its start bits, as a bucket stores it.
KDET_HD inline std::uint32_t tag_starts(std::uint32_t id, std::uint32_t starts) { return id | starts << grid_id_bits; }

/// @brief One id of a compacted cell with what a query filters on: what place_entry takes for each
/// id, and what a query's visitor gets for each entry that passes.
struct GridEntry {
    Aabb box;
    std::uint32_t id_and_starts; ///< tag_starts(id, starts)
    std::uint32_t object;
    KDET_HD std::uint32_t id() const { return id_and_starts & grid_id_mask; }
    KDET_HD std::uint32_t starts() const { return id_and_starts >> grid_id_bits; }
};

/// @brief Entries of the compacted lists per block: block b holds entries [b * entry_block,
/// (b + 1) * entry_block), whatever lists they belong to, and bounds their boxes, so that a query
/// skips the entries of a block whose bound misses its box without reading them.
constexpr std::uint32_t entry_block = 8;

/// @brief The compacted lists' entries, entry_block at a time, each field a row with a lane per
/// entry (entry k is lane k % entry_block of block k / entry_block): a query tests the boxes and
/// start bits of a whole block at once, which the host does in vector instructions without a branch
/// per entry. 32 bytes per entry, as a GridEntry.
struct EntryBlock {
    float lo[3][entry_block];
    float hi[3][entry_block];
    std::uint32_t id_and_starts[entry_block];
    std::uint32_t object[entry_block];
};

/// @brief Boxes stored as rows with a lane per box (EntryBlock's entries, BlockBoundGroup's blocks):
/// box i read, box i written, and whether box i overlaps `box` (closed boxes, without a branch, so
/// that a loop over the lanes becomes vector instructions on the host).
template <std::uint32_t Lanes>
KDET_HD KDET_ALWAYS_INLINE Aabb lane_box(const float (&lo)[3][Lanes], const float (&hi)[3][Lanes], std::uint32_t i) {
    return Aabb{{lo[0][i], lo[1][i], lo[2][i]}, {hi[0][i], hi[1][i], hi[2][i]}};
}
template <std::uint32_t Lanes>
KDET_HD KDET_ALWAYS_INLINE void set_lane_box(float (&lo)[3][Lanes], float (&hi)[3][Lanes], std::uint32_t i, const Aabb& box) {
    lo[0][i] = box.lo.x;
    lo[1][i] = box.lo.y;
    lo[2][i] = box.lo.z;
    hi[0][i] = box.hi.x;
    hi[1][i] = box.hi.y;
    hi[2][i] = box.hi.z;
}
template <std::uint32_t Lanes>
KDET_HD KDET_ALWAYS_INLINE bool lane_overlaps(const float (&lo)[3][Lanes], const float (&hi)[3][Lanes], std::uint32_t i,
                                              const Aabb& box) {
    return (lo[0][i] <= box.hi.x) & (box.lo.x <= hi[0][i]) & (lo[1][i] <= box.hi.y) & (box.lo.y <= hi[1][i]) &
           (lo[2][i] <= box.hi.z) & (box.lo.z <= hi[2][i]);
}

/// @brief Blocks of entries per group of their bounds: a query gathers a group's matches into one
/// 64-bit mask.
constexpr std::uint32_t bound_group = 64 / entry_block;
static_assert(bound_group * entry_block == 64 && bound_group <= 32, "a group's entries fill one 64-bit mask, its blocks a 32-bit one");

/// @brief The bounds of bound_group consecutive blocks of entries (group g: blocks [g * bound_group,
/// (g + 1) * bound_group)), each field a row with a lane per block, so that a query tests the bounds
/// of a whole group at once (see grid_for_each_in_entries): the box around the block's boxes and the
/// objects its entries belong to (object_bit of each). A list holds its ids in order, and an object's
/// tets are consecutive ids, so most blocks hold one object's entries, which a query checked only
/// against other objects skips unread (half the entries of two objects that overlap). Aligned to cache
/// lines: unaligned, the 224 bytes spread the box rows, which every query reads, over a fourth line.
struct alignas(64) BlockBoundGroup {
    float lo[3][bound_group];
    float hi[3][bound_group];
    std::uint32_t objects[bound_group];
};

/// @brief Where a tet sits in the cells of its own layer, so that its queries there need neither a
/// hash lookup nor a binary search: for cell lo + d of its range there (d.x + 2 d.y + 4 d.z, see
/// own_cell_index), the cell's main bucket, written while populating, and the position just after the
/// tet's entry in the cell's list, written while compacting. Kept for a tet whose range spans at most
/// two cells along each axis (has_own_cells): every tet but those that rounding or the top layer's cap
/// widens, which look their cells up.
struct OwnCells {
    std::uint32_t bucket[8];
    std::uint32_t after[8];
};

KDET_HD inline bool has_own_cells(const CellRange& r) {
    return r.hi[0] - r.lo[0] <= 1u && r.hi[1] - r.lo[1] <= 1u && r.hi[2] - r.lo[2] <= 1u;
}

/// @brief Index of cell (x, y, z) of range r in OwnCells, for a range with has_own_cells. The start
/// bits of the tet's entry there say the same: bit a is set when d along a is 0 (own_cell_index_of).
KDET_HD inline std::uint32_t own_cell_index(const CellRange& r, std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    return (x - r.lo[0]) + 2u * (y - r.lo[1]) + 4u * (z - r.lo[2]);
}
KDET_HD inline std::uint32_t own_cell_index_of(std::uint32_t starts) { return ~starts & 7u; }

/// @brief A plain view of the table's buffers, passed by value into per-element code.
struct GridView {
    BucketHeader* headers;          ///< slot_count main buckets, then overflow_capacity pool buckets
    std::uint32_t* ids;             ///< bucket_capacity ids per bucket
    EntryBlock* entry_blocks;       ///< the compacted cells' lists, [entry_capacity / entry_block rounded up]
    std::uint32_t* list_keys;       ///< [entry_capacity] the lists' entries as list keys, unsorted, while compacting
    std::uint32_t* list_begin;      ///< [slot_count] the range of the list of the cell claimed i-th, while compacting
    std::uint32_t* list_end;
    BlockBoundGroup* block_bounds;  ///< the bound of each block of entries, [blocks / bound_group rounded up]
    OwnCells* own_cells;            ///< [tets] for the pipeline's queries; null where none use them (the table's own tests)
    std::uint32_t* entries_used;
    std::uint32_t entry_capacity;
    std::uint32_t* overflow_used;   ///< pool buckets handed out this frame
    std::uint32_t* failure;         ///< GridFailure bits
    std::uint32_t* cells_claimed;   ///< main buckets claimed this frame (occupied cells)
    /// [slot_count] the main buckets in the order they were claimed this frame: compacting them in that
    /// order lays the lists out as the tets that claimed them lie (spatial order).
    std::uint32_t* claimed_slots;
    std::uint32_t slot_count;       ///< 2^slot_bits
    std::uint32_t slot_bits;
    std::uint32_t bucket_capacity;
    std::uint32_t overflow_capacity;
    std::uint32_t stamp;            ///< this frame's stamp, >= 1
    std::uint32_t max_probes;
    HashFunction hash;
};

/// @brief Finds or claims the main bucket of `cell`; no_bucket when max_probes slots are taken by other cells.
KDET_HD inline std::uint32_t claim_bucket(const GridView& g, CellCoord cell) {
    const std::uint64_t key = cell_key(cell);
    const std::uint32_t writing = g.stamp * 2u;
    const std::uint32_t ready = writing + 1u;
    const CellHash hash = hash_cell_part(g.hash, cell);
    for (std::uint32_t probe = 0; probe < g.max_probes; ++probe) {
        const std::uint32_t slot = table_slot(hash_probe(hash, probe), g.slot_bits);
        BucketHeader& h = g.headers[slot];
        std::uint32_t state = atomic_load_acquire(&h.state);
        if ((state >> 1) != g.stamp && atomic_compare_exchange(&h.state, state, writing)) {
            h.key = key;
            h.count = 0;
            h.next = no_bucket;
            h.tail = slot;
            atomic_store_release(&h.state, ready);
            // One counter for every cell claimed: on a GPU the claims of a warp take one atomic.
            const std::uint32_t order = atomic_fetch_add_gathered(g.cells_claimed, 1u);
            g.claimed_slots[order] = slot;
            return slot;
        }
        // Claimed this frame by someone (maybe just now): wait until its key is visible.
        while (state != ready) state = atomic_load_acquire(&h.state);
        if (h.key == key) return slot;
    }
    atomic_fetch_or(g.failure, static_cast<std::uint32_t>(grid_table_full));
    return no_bucket;
}

/// @brief Appends `id` to the chain of main bucket `main`, chaining pool buckets when full. It starts
/// at the chain's last bucket as far as it is known (BucketHeader::tail) and passes a full bucket
/// without an atomic add on its count: inserts into a cell of many ids took one per bucket of the
/// chain.
KDET_HD inline bool append_to_chain(const GridView& g, std::uint32_t main, std::uint32_t id) {
    std::uint32_t bucket = atomic_load_acquire(&g.headers[main].tail);
    for (;;) {
        BucketHeader& h = g.headers[bucket];
        if (atomic_load_acquire(&h.count) < g.bucket_capacity) {
            const std::uint32_t index = atomic_fetch_add(&h.count, 1u);
            if (index < g.bucket_capacity) {
                g.ids[static_cast<std::uint64_t>(bucket) * g.bucket_capacity + index] = id;
                return true;
            }
        }
        std::uint32_t next = atomic_load_acquire(&h.next);
        if (next == no_bucket) {
            const std::uint32_t taken = atomic_fetch_add(g.overflow_used, 1u);
            if (taken >= g.overflow_capacity) {
                atomic_fetch_or(g.failure, static_cast<std::uint32_t>(grid_overflow_pool_full));
                return false;
            }
            const std::uint32_t fresh = g.slot_count + taken;
            BucketHeader& f = g.headers[fresh];
            f.key = h.key;
            f.count = 0;
            f.next = no_bucket;
            f.state = g.stamp * 2u + 1u;
            // Losing the race leaves `fresh` unused for this frame; the winner's bucket is followed.
            if (atomic_compare_exchange(&h.next, next, fresh)) {
                next = fresh;
                // A tail stored late by a slower winner points a few buckets back: still in the chain.
                atomic_store_release(&g.headers[main].tail, fresh);
            }
        }
        bucket = next;
    }
}

/// @brief Inserts `id` into `cell`, with the axes along which its box starts there (`starts`, bit a
/// for axis a); returns the cell's main bucket, or no_bucket (with a failure bit set) when the table
/// must grow.
KDET_HD inline std::uint32_t grid_insert(const GridView& g, CellCoord cell, std::uint32_t id, std::uint32_t starts) {
    const std::uint32_t bucket = claim_bucket(g, cell);
    return bucket != no_bucket && append_to_chain(g, bucket, tag_starts(id, starts)) ? bucket : no_bucket;
}

/// @brief Main bucket of `cell` after populating, or no_bucket when the cell is empty.
KDET_HD inline std::uint32_t grid_find(const GridView& g, CellCoord cell) {
    const std::uint64_t key = cell_key(cell);
    const CellHash hash = hash_cell_part(g.hash, cell);
    for (std::uint32_t probe = 0; probe < g.max_probes; ++probe) {
        const std::uint32_t slot = table_slot(hash_probe(hash, probe), g.slot_bits);
        const BucketHeader& h = g.headers[slot];
        if ((h.state >> 1) != g.stamp) return no_bucket;
        if (h.key == key) return slot;
    }
    return no_bucket;
}

/// @brief The id (with its start bits) of entry k of the compacted lists.
KDET_HD inline std::uint32_t& entry_id_and_starts(const GridView& g, std::uint32_t k) {
    return g.entry_blocks[k / entry_block].id_and_starts[k % entry_block];
}

/// @brief Entry k of the compacted lists, gathered from its block's rows.
KDET_HD KDET_ALWAYS_INLINE GridEntry load_entry(const GridView& g, std::uint32_t k) {
    const EntryBlock& b = g.entry_blocks[k / entry_block];
    const std::uint32_t i = k % entry_block;
    return GridEntry{lane_box(b.lo, b.hi, i), b.id_and_starts[i], b.object[i]};
}

/// @brief A list entry's sort key: the id above its start bits, so that the keys of a list sort by id
/// (a tet is in a cell's list once).
KDET_HD inline std::uint32_t list_key(std::uint32_t tagged) { return (tagged & grid_id_mask) << 3 | tagged >> grid_id_bits; }
KDET_HD inline std::uint32_t tagged_of_list_key(std::uint32_t key) { return tag_starts(key >> 3, key & 7u); }

/// @brief Compacting, step 1 of 3, for the cell claimed `order`-th this frame (any order at or past
/// the count of claimed cells holds none): claims room for the cell's ids in the lists, copies them
/// there as list keys (GridView::list_keys, unsorted), sets the main bucket's objects (object_bit of
/// object_of(id) of each id), points the main bucket at the list, and records the list's range as list
/// `order` (empty for none). When the list does not fit, the cell reads as empty and
/// grid_entries_full is set: the frame reruns with more room. Step 2 sorts each list by id into a
/// second array (the execution layer's sort_lists: on the GPU many threads share a long list, where
/// one thread sorting it took milliseconds), step 3 fills each entry's rows from its sorted key
/// (place_entry).
template <class ObjectOf>
KDET_HD inline void gather_cell(const GridView& g, std::uint32_t order, const ObjectOf& object_of) {
    g.list_begin[order] = g.list_end[order] = 0;
    if (order >= *g.cells_claimed) return;
    BucketHeader& main = g.headers[g.claimed_slots[order]];
    std::uint32_t total = 0;
    for (std::uint32_t b = g.claimed_slots[order]; b != no_bucket; b = g.headers[b].next)
        total += g.headers[b].count < g.bucket_capacity ? g.headers[b].count : g.bucket_capacity;
    // One counter for every list: on a GPU a warp's lists take one atomic (each claimed cell took
    // its own, and they queued on the one address).
    const std::uint32_t first = atomic_fetch_add_gathered(g.entries_used, total);
    if (first > g.entry_capacity || total > g.entry_capacity - first) {
        atomic_fetch_or(g.failure, static_cast<std::uint32_t>(grid_entries_full));
        main.count = 0;
        main.first_entry = 0;
        main.objects = 0;
        return;
    }
    std::uint32_t k = first, objects = 0;
    for (std::uint32_t b = g.claimed_slots[order]; b != no_bucket; b = g.headers[b].next) {
        const std::uint32_t n = g.headers[b].count < g.bucket_capacity ? g.headers[b].count : g.bucket_capacity;
        const std::uint32_t* ids = g.ids + static_cast<std::uint64_t>(b) * g.bucket_capacity;
        for (std::uint32_t i = 0; i < n; ++i) {
            g.list_keys[k++] = list_key(ids[i]);
            objects |= object_bit(object_of(ids[i] & grid_id_mask));
        }
    }
    main.count = total;
    main.first_entry = first;
    main.objects = objects;
    g.list_begin[order] = first;
    g.list_end[order] = first + total;
}

/// @brief Compacting, step 3 of 3: entry k of the lists (below the entries claimed, in a list that
/// fitted) from its key in the sorted lists: its id and start bits, and entry_of(id)'s box and
/// object, in its block's rows, and the position after it in its tet's own cells (OwnCells::after).
template <class EntryOf>
KDET_HD inline void place_entry(const GridView& g, const std::uint32_t* sorted_keys, std::uint32_t k, const EntryOf& entry_of) {
    const std::uint32_t tagged = tagged_of_list_key(sorted_keys[k]);
    const GridEntry e = entry_of(tagged & grid_id_mask);
    EntryBlock& block = g.entry_blocks[k / entry_block];
    const std::uint32_t i = k % entry_block;
    block.id_and_starts[i] = tagged;
    set_lane_box(block.lo, block.hi, i, e.box);
    block.object[i] = e.object;
    if (g.own_cells)
        // Relaxed atomic: for a tet spanning more than two cells along an axis (which keeps no row)
        // two cells' entries may store to the same slot.
        atomic_store_relaxed(&g.own_cells[tagged & grid_id_mask].after[own_cell_index_of(tagged >> grid_id_bits)], k + 1);
}

/// @brief The bound of block `block` of the compacted entries (see entry_block), once every list is
/// written (`used` entries claimed in all, which may exceed the room when a list did not fit);
/// blocks past them are left alone.
KDET_HD inline void bound_entry_block(const GridView& g, std::uint32_t block, std::uint32_t used) {
    if (used > g.entry_capacity) used = g.entry_capacity;
    const std::uint32_t begin = block * entry_block;
    if (begin >= used) return;
    const std::uint32_t end = used - begin < entry_block ? used : begin + entry_block;
    const GridEntry first = load_entry(g, begin);
    Aabb bound = first.box;
    std::uint32_t objects = object_bit(first.object);
    for (std::uint32_t k = begin + 1; k < end; ++k) {
        const GridEntry e = load_entry(g, k);
        bound.lo = min_v(bound.lo, e.box.lo);
        bound.hi = max_v(bound.hi, e.box.hi);
        objects |= object_bit(e.object);
    }
    BlockBoundGroup& group = g.block_bounds[block / bound_group];
    set_lane_box(group.lo, group.hi, block % bound_group, bound);
    group.objects[block % bound_group] = objects;
}

/// @brief The bound of block `block`, as bound_entry_block stored it.
KDET_HD inline Aabb block_bound(const GridView& g, std::uint32_t block) {
    const BlockBoundGroup& group = g.block_bounds[block / bound_group];
    return lane_box(group.lo, group.hi, block % bound_group);
}

/// @brief The blocks of a group whose bounds overlap `box` and that hold an entry of one of `objects`
/// (object_bit of each; any_object reads no block's objects), as a mask (bit i for lane i), every lane
/// computed without a branch (see matching_lanes); the caller masks the blocks outside its list.
KDET_HD KDET_ALWAYS_INLINE std::uint32_t overlapping_blocks(const BlockBoundGroup& g, const Aabb& box, std::uint32_t objects) {
    std::uint32_t lanes[bound_group];
    if (objects == any_object) {
        KDET_VECTOR_LOOP
        for (std::uint32_t i = 0; i < bound_group; ++i) lanes[i] = lane_overlaps(g.lo, g.hi, i, box) ? ~0u : 0u;
    } else {
        KDET_VECTOR_LOOP
        for (std::uint32_t i = 0; i < bound_group; ++i)
            lanes[i] = lane_overlaps(g.lo, g.hi, i, box) & ((g.objects[i] & objects) != 0u) ? ~0u : 0u;
    }
    return lane_bits(lanes);
}

/// @brief The lanes of a block whose boxes overlap `box` and whose start bits include `required_starts`,
/// as a mask (bit i for lane i). Every lane is computed, without a branch, so that the host's compiler
/// turns the loop into a few vector instructions per block where a branch per entry mispredicts about
/// as often as a box overlaps; the caller masks the lanes outside its list.
KDET_HD KDET_ALWAYS_INLINE std::uint32_t matching_lanes(const EntryBlock& b, const Aabb& box, std::uint32_t required_starts) {
    std::uint32_t lanes[entry_block];
    KDET_VECTOR_LOOP
    for (std::uint32_t i = 0; i < entry_block; ++i) {
        const bool overlaps = lane_overlaps(b.lo, b.hi, i, box);
        const bool starts = ((b.id_and_starts[i] >> grid_id_bits) & required_starts) == required_starts;
        lanes[i] = overlaps & starts ? ~0u : 0u;
    }
    return lane_bits(lanes);
}

/// @brief Bits [first, end) of a 64-bit mask, 0 <= first < end <= 64, without a branch.
KDET_HD KDET_ALWAYS_INLINE std::uint64_t bit_range(std::uint32_t first, std::uint32_t end) {
    return (~0ull << first) & (~0ull >> (64u - end));
}

/// @brief Index of the lowest set bit of a non-zero mask, of 64 bits or (below) of 32.
KDET_HD inline std::uint32_t lowest_bit(std::uint64_t mask) {
#if defined(__CUDA_ARCH__)
    return static_cast<std::uint32_t>(__ffsll(static_cast<long long>(mask)) - 1);
#else
    return static_cast<std::uint32_t>(__builtin_ctzll(mask));
#endif
}

KDET_HD inline std::uint32_t lowest_bit(std::uint32_t mask) {
#if defined(__CUDA_ARCH__)
    return static_cast<std::uint32_t>(__ffs(static_cast<int>(mask)) - 1);
#else
    return static_cast<std::uint32_t>(__builtin_ctz(mask));
#endif
}

/// @brief Every block of a group (the scans' `group_blocks`).
constexpr std::uint32_t all_group_blocks = (1u << bound_group) - 1u;

/// @brief The blocks of each group that part `part` of a scan shared by `parts` work items reads:
/// block i of a group where i % parts == part (parts divides bound_group), so that the parts together
/// read every block once, neighbouring parts neighbouring blocks.
KDET_HD constexpr std::uint32_t group_blocks_of_part(std::uint32_t part, std::uint32_t parts) {
    if (parts == 1) return all_group_blocks; // the CPU's whole searches: no loop per tet
    std::uint32_t blocks = 0;
    for (std::uint32_t i = part; i < bound_group; i += parts) blocks |= 1u << i;
    return blocks;
}

/// @brief Calls visit(entry) for every entry k in [begin, end) of the compacted lists (begin < end) whose
/// box overlaps `box` and whose start bits include `required_starts` (see GridEntry::starts), in the
/// blocks of each group that `group_blocks` names; the entries of a block whose bound misses `box`, or
/// which holds none of the `objects` (object_bit of each, or any_object), are not read. The visitor
/// checks the entry's object itself. A group of blocks at a time: its bounds tested at once, its
/// matches gathered into one mask and visited in one loop, where a branch per block on its bound and a
/// loop per block over its matches each mispredicted about once a block.
template <class Visitor>
KDET_HD inline void grid_for_each_in_entries(const GridView& g, std::uint32_t begin, std::uint32_t end, const Aabb& box,
                                             std::uint32_t objects, std::uint32_t required_starts, Visitor& visit,
                                             std::uint32_t group_blocks = all_group_blocks) {
    // Copies: the visitor's stores might alias them for all the compiler knows, which would have
    // every block reload the box and spread it over the vector lanes again.
    const Aabb query = box;
    const EntryBlock* const blocks = g.entry_blocks;
    const BlockBoundGroup* const bounds = g.block_bounds;
    const std::uint32_t first_block = begin / entry_block, last_block = (end - 1) / entry_block;
    for (std::uint32_t group = first_block / bound_group; group <= last_block / bound_group; ++group) {
        const std::uint32_t group_block = group * bound_group;
        // The blocks and lanes outside the range masked without a branch (which mispredicted about once
        // per query): the range's ends within the group by selects, then bit_range.
        const std::uint32_t blocks_before = first_block > group_block ? first_block - group_block : 0u;
        const std::uint32_t blocks_in_range = last_block - group_block < bound_group ? last_block - group_block + 1 : bound_group;
        std::uint32_t passing = overlapping_blocks(bounds[group], query, objects) & group_blocks &
                                static_cast<std::uint32_t>(bit_range(blocks_before, blocks_in_range));
        std::uint64_t matches = 0;
        while (passing) {
            const std::uint32_t k = lowest_bit(passing);
            passing &= passing - 1u;
            matches |= static_cast<std::uint64_t>(matching_lanes(blocks[group_block + k], query, required_starts))
                       << (k * entry_block);
        }
        const std::uint32_t base = group_block * entry_block, group_entries = bound_group * entry_block;
        const std::uint32_t entries_before = begin > base ? begin - base : 0u;
        const std::uint32_t entries_in_range = end - base < group_entries ? end - base : group_entries;
        matches &= bit_range(entries_before, entries_in_range);
        while (matches) {
            visit(load_entry(g, base + lowest_bit(matches)));
            matches &= matches - 1ull;
        }
    }
}

/// @brief Calls visit(entry) for every entry of `cell` whose id is at least `first_id`, whose box
/// overlaps `box` and whose start bits include `required_starts`, once the table is compacted, unless
/// the cell holds none of the `objects` (object_bit of each, or any_object): the smaller ids are
/// skipped by a binary search (grid_for_each_in_entries for the rest, in the blocks `group_blocks`
/// names). The visitor checks the entry's object itself.
template <class Visitor>
KDET_HD inline void grid_for_each_in_cell(const GridView& g, CellCoord cell, std::uint32_t first_id, std::uint32_t objects,
                                          const Aabb& box, std::uint32_t required_starts, Visitor& visit,
                                          std::uint32_t group_blocks = all_group_blocks) {
    const std::uint32_t bucket = grid_find(g, cell);
    if (bucket == no_bucket || !(g.headers[bucket].objects & objects)) return;
    const std::uint32_t first = g.headers[bucket].first_entry;
    const std::uint32_t end = first + g.headers[bucket].count;
    std::uint32_t begin = first;
    // With first_id 0 (a higher layer, where every tet is larger) the search would only read ids.
    for (std::uint32_t high = first_id ? end : first; begin < high;) {
        const std::uint32_t middle = begin + (high - begin) / 2;
        if ((entry_id_and_starts(g, middle) & grid_id_mask) < first_id)
            begin = middle + 1;
        else
            high = middle;
    }
    if (begin < end) grid_for_each_in_entries(g, begin, end, box, objects, required_starts, visit, group_blocks);
}

/// @brief grid_for_each_in_cell on cell `index` of tet `id`'s own cells (OwnCells) with first_id
/// id + 1, found through the tet's row. A row left over from an earlier frame (when this frame's grid
/// failed and will run again) reads only entries of this frame's lists.
template <class Visitor>
KDET_HD inline void grid_for_each_after_own_entry(const GridView& g, std::uint32_t id, std::uint32_t index,
                                                  std::uint32_t objects, const Aabb& box, std::uint32_t required_starts,
                                                  Visitor& visit, std::uint32_t group_blocks = all_group_blocks) {
    const OwnCells& row = g.own_cells[id];
    const std::uint32_t bucket = row.bucket[index];
    if (bucket >= g.slot_count) return;
    const BucketHeader& h = g.headers[bucket];
    if ((h.state >> 1) != g.stamp || !(h.objects & objects)) return;
    const std::uint32_t first = h.first_entry, end = first + h.count;
    const std::uint32_t begin = row.after[index] > first ? row.after[index] : first;
    if (begin < end) grid_for_each_in_entries(g, begin, end, box, objects, required_starts, visit, group_blocks);
}

} // namespace kdet
