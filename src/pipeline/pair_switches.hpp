#pragma once
/// @file pair_switches.hpp
/// @brief The detector's switch per pair of objects (and per object with itself: self-collision), on the
/// host. Rows are stored with a stride that doubles as objects are added, so that adding n objects one
/// by one copies O(n^2) cells in all rather than the whole table on every add.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace kdet {

class PairSwitches {
public:
    std::size_t objects() const { return objects_; }
    std::uint8_t& operator()(std::size_t a, std::size_t b) { return cells_[a * stride_ + b]; }
    std::uint8_t operator()(std::size_t a, std::size_t b) const { return cells_[a * stride_ + b]; }

    /// @brief Adds an object, on against every other object and off with itself.
    void add_object() {
        if (objects_ == stride_) {
            const std::size_t stride = std::max<std::size_t>(4, 2 * stride_);
            std::vector<std::uint8_t> cells(stride * stride, 0);
            for (std::size_t a = 0; a < objects_; ++a)
                std::copy_n(cells_.begin() + static_cast<std::ptrdiff_t>(a * stride_), objects_,
                            cells.begin() + static_cast<std::ptrdiff_t>(a * stride));
            cells_.swap(cells);
            stride_ = stride;
        }
        const std::size_t added = objects_++;
        for (std::size_t other = 0; other < objects_; ++other) (*this)(added, other) = (*this)(other, added) = other != added;
    }

    /// @brief The switches as the pipeline takes them: [a * objects() + b].
    std::vector<std::uint8_t> table() const {
        std::vector<std::uint8_t> out(objects_ * objects_);
        for (std::size_t a = 0; a < objects_; ++a)
            std::copy_n(cells_.begin() + static_cast<std::ptrdiff_t>(a * stride_), objects_,
                        out.begin() + static_cast<std::ptrdiff_t>(a * objects_));
        return out;
    }

private:
    std::vector<std::uint8_t> cells_;
    std::size_t objects_ = 0, stride_ = 0;
};

} // namespace kdet
