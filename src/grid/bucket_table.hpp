#pragma once
/// @file bucket_table.hpp
/// @brief The hash table that stores the grid: fixed-capacity buckets, rehash probing on misses,
/// overflow buckets chained per cell, and a frame stamp so the table never needs clearing. Once
/// filled, each cell's chain is copied into one contiguous list of entries sorted by id
/// (compact_cell), which is what queries read.
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
    std::uint64_t key;
};

/// @brief An object's bit in BucketHeader::objects and in the query's mask of objects it is checked
/// against; objects 32 apart share a bit, which only costs a cell read for nothing.
KDET_HD inline std::uint32_t object_bit(std::uint32_t object) { return 1u << (object & 31u); }

/// @brief The mask of a query that is checked against every object.
constexpr std::uint32_t any_object = ~0u;

/// @brief Bits of an id as the buckets and lists store it; above them, the axes along which the id's
/// box starts in the cell (bit a: its first cell along axis a is this one), which decides the cell
/// a pair is reported from. Tet ids stay below 2^grid_id_bits (Detector checks).
constexpr int grid_id_bits = 29;
constexpr std::uint32_t grid_id_mask = (1u << grid_id_bits) - 1u;

/// @brief An id with its start bits, as a bucket stores it.
KDET_HD inline std::uint32_t tag_starts(std::uint32_t id, std::uint32_t starts) { return id | starts << grid_id_bits; }

/// @brief One id of a compacted cell with what a query filters on, so that scanning a cell reads
/// one contiguous list instead of each id's data wherever it lies.
struct GridEntry {
    Aabb box;
    std::uint32_t id_and_starts; ///< tag_starts(id, starts)
    std::uint32_t object;
    KDET_HD std::uint32_t id() const { return id_and_starts & grid_id_mask; }
    KDET_HD std::uint32_t starts() const { return id_and_starts >> grid_id_bits; }
};

/// @brief Entries of the compacted lists per block: block b bounds the boxes of entries
/// [b * entry_block, (b + 1) * entry_block), whatever lists they belong to, so that a query skips the
/// entries of a block whose bound misses its box without reading them.
constexpr std::uint32_t entry_block = 8;

/// @brief A plain view of the table's buffers, passed by value into per-element code.
struct GridView {
    BucketHeader* headers;          ///< slot_count main buckets, then overflow_capacity pool buckets
    std::uint32_t* ids;             ///< bucket_capacity ids per bucket
    GridEntry* entries;             ///< the compacted cells' lists
    Aabb* block_bounds;             ///< [entry_capacity / entry_block rounded up] the bound of each block of entries
    std::uint32_t* entries_used;
    std::uint32_t entry_capacity;
    std::uint32_t* overflow_used;   ///< pool buckets handed out this frame
    std::uint32_t* failure;         ///< GridFailure bits
    std::uint32_t* cells_claimed;   ///< main buckets claimed this frame (occupied cells)
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
            atomic_store_release(&h.state, ready);
            atomic_fetch_add(g.cells_claimed, 1u);
            return slot;
        }
        // Claimed this frame by someone (maybe just now): wait until its key is visible.
        while (state != ready) state = atomic_load_acquire(&h.state);
        if (h.key == key) return slot;
    }
    atomic_fetch_or(g.failure, static_cast<std::uint32_t>(grid_table_full));
    return no_bucket;
}

/// @brief Appends `id` to the chain that starts at `bucket`, chaining pool buckets when full.
KDET_HD inline bool append_to_chain(const GridView& g, std::uint32_t bucket, std::uint32_t id) {
    for (;;) {
        BucketHeader& h = g.headers[bucket];
        const std::uint32_t index = atomic_fetch_add(&h.count, 1u);
        if (index < g.bucket_capacity) {
            g.ids[static_cast<std::uint64_t>(bucket) * g.bucket_capacity + index] = id;
            return true;
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
            if (atomic_compare_exchange(&h.next, next, fresh)) next = fresh;
        }
        bucket = next;
    }
}

/// @brief Inserts `id` into `cell`, with the axes along which its box starts there (`starts`, bit a
/// for axis a); false (with a failure bit set) when the table must grow.
KDET_HD inline bool grid_insert(const GridView& g, CellCoord cell, std::uint32_t id, std::uint32_t starts) {
    const std::uint32_t bucket = claim_bucket(g, cell);
    return bucket != no_bucket && append_to_chain(g, bucket, tag_starts(id, starts));
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

/// @brief Copies the ids of the cell whose main bucket is `slot` (if it is occupied this frame) into
/// one list of entries, entry_of(id) each with the id's start bits, sorted by id, and points the main
/// bucket at it. When the list does not fit, the cell reads as empty and grid_entries_full is set:
/// the frame reruns with more room.
template <class EntryOf>
KDET_HD inline void compact_cell(const GridView& g, std::uint32_t slot, const EntryOf& entry_of) {
    BucketHeader& main = g.headers[slot];
    if ((main.state >> 1) != g.stamp) return;
    std::uint32_t total = 0;
    for (std::uint32_t b = slot; b != no_bucket; b = g.headers[b].next)
        total += g.headers[b].count < g.bucket_capacity ? g.headers[b].count : g.bucket_capacity;
    const std::uint32_t first = atomic_fetch_add(g.entries_used, total);
    if (first > g.entry_capacity || total > g.entry_capacity - first) {
        atomic_fetch_or(g.failure, static_cast<std::uint32_t>(grid_entries_full));
        main.count = 0;
        main.first_entry = 0;
        main.objects = 0;
        return;
    }
    std::uint32_t k = first, objects = 0;
    for (std::uint32_t b = slot; b != no_bucket; b = g.headers[b].next) {
        const std::uint32_t n = g.headers[b].count < g.bucket_capacity ? g.headers[b].count : g.bucket_capacity;
        const std::uint32_t* ids = g.ids + static_cast<std::uint64_t>(b) * g.bucket_capacity;
        for (std::uint32_t i = 0; i < n; ++i) {
            GridEntry e = entry_of(ids[i] & grid_id_mask);
            e.id_and_starts = ids[i];
            objects |= object_bit(e.object);
            g.entries[k++] = e;
        }
    }
    // Insertion sort: threads populate in about id order, so few entries move.
    for (std::uint32_t i = first + 1; i < first + total; ++i) {
        const GridEntry e = g.entries[i];
        std::uint32_t j = i;
        for (; j > first && g.entries[j - 1].id() > e.id(); --j) g.entries[j] = g.entries[j - 1];
        g.entries[j] = e;
    }
    main.count = total;
    main.first_entry = first;
    main.objects = objects;
}

/// @brief The bound of block `block` of the compacted entries (see entry_block), once every list is
/// written (`used` entries claimed in all, which may exceed the room when a list did not fit);
/// blocks past them are left alone.
KDET_HD inline void bound_entry_block(const GridView& g, std::uint32_t block, std::uint32_t used) {
    if (used > g.entry_capacity) used = g.entry_capacity;
    const std::uint32_t begin = block * entry_block;
    if (begin >= used) return;
    const std::uint32_t end = used - begin < entry_block ? used : begin + entry_block;
    Aabb bound = g.entries[begin].box;
    for (std::uint32_t k = begin + 1; k < end; ++k) {
        bound.lo = min_v(bound.lo, g.entries[k].box.lo);
        bound.hi = max_v(bound.hi, g.entries[k].box.hi);
    }
    g.block_bounds[block] = bound;
}

/// @brief Calls visit(entry) for every entry of `cell` whose id is at least `first_id` and whose box
/// may overlap `box`, once the table is compacted, unless the cell holds none of the `objects`
/// (object_bit of each, or any_object): the smaller ids are skipped by a binary search, and the
/// entries of a block whose bound misses `box` without being read (the visitor still tests each box
/// and object it gets).
template <class Visitor>
KDET_HD inline void grid_for_each_in_cell(const GridView& g, CellCoord cell, std::uint32_t first_id, std::uint32_t objects,
                                          const Aabb& box, Visitor& visit) {
    const std::uint32_t bucket = grid_find(g, cell);
    if (bucket == no_bucket || !(g.headers[bucket].objects & objects)) return;
    const std::uint32_t first = g.headers[bucket].first_entry;
    const GridEntry* entries = g.entries + first;
    const std::uint32_t n = g.headers[bucket].count;
    std::uint32_t begin = 0;
    for (std::uint32_t end = n; begin < end;) {
        const std::uint32_t middle = begin + (end - begin) / 2;
        if (entries[middle].id() < first_id)
            begin = middle + 1;
        else
            end = middle;
    }
    for (std::uint32_t k = begin; k < n;) {
        const std::uint32_t block = (first + k) / entry_block;
        const std::uint32_t block_end = (block + 1) * entry_block - first;
        const std::uint32_t end = block_end < n ? block_end : n;
        if (!boxes_overlap(box, g.block_bounds[block])) {
            k = end;
            continue;
        }
        for (; k < end; ++k) visit(entries[k]);
    }
}

} // namespace kdet
