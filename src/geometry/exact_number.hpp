#pragma once
/// @file exact_number.hpp
/// @brief Exact sums and products of floats for polynomials of degree up to 6 in differences of float
/// coordinates: the exact stage of the margin decision (tet_distance.hpp), whose squared distances
/// are of degree 6 where exact_sum.hpp's determinants are of degree 3.
///
/// A number is sign * magnitude * 2^exponent with the magnitude an integer of up to k_limbs limbs of
/// 32 bits. A float is m 2^e with m < 2^24 and -149 <= e <= 104, so a product of k differences of
/// floats is a multiple of 2^(-149 k) below 2^(129 k): at degree 6 a span of 1668 bits, plus a few for
/// the sums, 54 limbs at most however the exponent falls within a limb (a product of two numbers of
/// degree 3, 28 limbs each, takes 56). k_limbs = 64 holds every value the margin decision forms.
/// Integer operations only: the result depends on no rounding mode, fused multiply-add or backend.
/// Operations keep only the limbs in use, so a number of everyday coordinates takes a few limbs.

#include "geometry/exact_sum.hpp"

#include <cstdint>

namespace kdet::exact {

class Number {
public:
    static constexpr int k_limbs = 64;

    KDET_HD Number() {}

    KDET_HD static Number of(float value) {
        const FloatParts p = float_parts(value);
        Number n;
        if (p.m == 0) return n;
        n.limb_[0] = p.m;
        n.used_ = 1;
        n.exponent_ = p.e;
        n.negative_ = p.negative;
        return n;
    }

    /// @brief -1, 0 or +1.
    KDET_HD int sign() const { return used_ == 0 ? 0 : (negative_ ? -1 : 1); }

    KDET_HD friend Number operator+(const Number& x, const Number& y) { return sum(x, y, false); }
    KDET_HD friend Number operator-(const Number& x, const Number& y) { return sum(x, y, true); }

    KDET_HD friend Number operator*(const Number& x, const Number& y) { return product(x, y); }

private:
    // Each expression of the margin decision instantiates its own chain of these operations: kept out
    // of line, they are compiled once, not once per expression (which ptxas takes very long over).
    KDET_NOINLINE KDET_HD static Number product(const Number& x, const Number& y) {
        Number r;
        if (x.used_ == 0 || y.used_ == 0) return r;
        const int n = x.used_ + y.used_ <= k_limbs ? x.used_ + y.used_ : k_limbs;
        KDET_NO_UNROLL
        for (int k = 0; k < n; ++k) r.limb_[k] = 0;
        KDET_NO_UNROLL
        for (int i = 0; i < x.used_; ++i) {
            std::uint64_t carry = 0;
            KDET_NO_UNROLL
            for (int j = 0; j < y.used_ && i + j < n; ++j) {
                const std::uint64_t t = static_cast<std::uint64_t>(x.limb_[i]) * y.limb_[j] + r.limb_[i + j] + carry;
                r.limb_[i + j] = static_cast<std::uint32_t>(t);
                carry = t >> 32;
            }
            if (i + y.used_ < n) r.limb_[i + y.used_] = static_cast<std::uint32_t>(carry);
        }
        r.used_ = n;
        r.exponent_ = x.exponent_ + y.exponent_;
        r.negative_ = x.negative_ != y.negative_;
        r.trim();
        return r;
    }

    /// @brief x + y, or x - y with `subtract`: both magnitudes in units of the smaller exponent, then
    /// added or the smaller taken from the larger.
    KDET_NOINLINE KDET_HD static Number sum(const Number& x, const Number& y, bool subtract) {
        const bool y_negative = y.negative_ != subtract;
        if (y.used_ == 0) return x;
        if (x.used_ == 0) {
            Number r = y;
            r.negative_ = y_negative;
            return r;
        }
        const int exponent = x.exponent_ < y.exponent_ ? x.exponent_ : y.exponent_;
        std::uint32_t a[k_limbs], b[k_limbs];
        const int na = x.aligned(exponent, a), nb = y.aligned(exponent, b);
        const int n = na > nb ? na : nb;
        KDET_NO_UNROLL
        for (int k = na; k < n; ++k) a[k] = 0;
        KDET_NO_UNROLL
        for (int k = nb; k < n; ++k) b[k] = 0;
        Number r;
        r.exponent_ = exponent;
        if (x.negative_ == y_negative) {
            std::uint64_t carry = 0;
            KDET_NO_UNROLL
            for (int k = 0; k < n; ++k) {
                const std::uint64_t t = static_cast<std::uint64_t>(a[k]) + b[k] + carry;
                r.limb_[k] = static_cast<std::uint32_t>(t);
                carry = t >> 32;
            }
            r.used_ = n;
            if (carry && n < k_limbs) r.limb_[r.used_++] = static_cast<std::uint32_t>(carry);
            r.negative_ = x.negative_;
        } else {
            int k = n - 1;
            while (k >= 0 && a[k] == b[k]) --k;
            if (k < 0) return Number{};
            const bool a_larger = a[k] > b[k];
            const std::uint32_t* big = a_larger ? a : b;
            const std::uint32_t* small = a_larger ? b : a;
            std::int64_t borrow = 0;
            KDET_NO_UNROLL
            for (int i = 0; i < n; ++i) {
                const std::int64_t t = static_cast<std::int64_t>(big[i]) - small[i] - borrow;
                borrow = t < 0 ? 1 : 0;
                r.limb_[i] = static_cast<std::uint32_t>(t + (borrow << 32));
            }
            r.used_ = n;
            r.negative_ = a_larger ? x.negative_ : y_negative;
        }
        r.trim();
        return r;
    }

    /// @brief The magnitude in units of 2^exponent (at most this number's), into out; returns the limbs.
    KDET_HD int aligned(int exponent, std::uint32_t out[k_limbs]) const {
        const int shift = exponent_ - exponent, words = shift >> 5, bits = shift & 31;
        int n = used_ + words + 1 <= k_limbs ? used_ + words + 1 : k_limbs;
        KDET_NO_UNROLL
        for (int k = 0; k < n; ++k) out[k] = 0;
        KDET_NO_UNROLL
        for (int k = 0; k < used_ && k + words < n; ++k) {
            const std::uint64_t v = static_cast<std::uint64_t>(limb_[k]) << bits;
            out[k + words] |= static_cast<std::uint32_t>(v);
            if (k + words + 1 < n) out[k + words + 1] |= static_cast<std::uint32_t>(v >> 32);
        }
        while (n > 0 && out[n - 1] == 0) --n;
        return n;
    }

    /// @brief Drops zero limbs at the top, and at the bottom (into the exponent).
    KDET_HD void trim() {
        while (used_ > 0 && limb_[used_ - 1] == 0) --used_;
        int low = 0;
        while (low < used_ && limb_[low] == 0) ++low;
        if (low == 0) return;
        KDET_NO_UNROLL
        for (int k = low; k < used_; ++k) limb_[k - low] = limb_[k];
        used_ -= low;
        exponent_ += 32 * low;
    }

    std::uint32_t limb_[k_limbs];
    int used_ = 0;
    int exponent_ = 0;
    bool negative_ = false;
};

} // namespace kdet::exact
