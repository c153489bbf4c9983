#pragma once
/// @file exact_sum.hpp
/// @brief Exact signs of determinants of differences of float points: the exact stage of the `exact`
/// narrow-phase test (exact_test.hpp).
///
/// Every float is m * 2^e with an integer 0 <= m < 2^24 and -149 <= e <= 104. A product of two or three
/// floats is therefore an integer of at most 48 or 72 bits times a power of two from 2^-447 up, and a
/// determinant whose rows are differences of float points expands, by multilinearity, into a signed
/// sum of such products: 8 for a 2x2 determinant, 48 for a 3x3 one. ExactSum adds those products
/// into one fixed-point integer in units of 2^-447 with 28 limbs of 32 bits (values up to 2^449), so the
/// sum is exact and its sign is the determinant's sign. No rounding happens anywhere: the result does
/// not depend on the rounding mode, on fused multiply-adds or on the backend, and the state is 224
/// bytes of stack (no heap, no floating-point expansions of data-dependent length). Floats are decoded
/// where they are used, so nothing else needs an array.

#include <cstdint>

#include "geometry/vec3.hpp"

namespace kdet::exact {

/// @brief A float as sign, integer significand and exponent: value = (negative ? -1 : 1) * m * 2^e.
struct FloatParts {
    std::uint32_t m; ///< < 2^24; 0 for zero
    int e;           ///< -149 .. 104 for finite floats
    bool negative;
};

KDET_HD inline FloatParts float_parts(float value) {
    std::uint32_t bits;
    __builtin_memcpy(&bits, &value, sizeof bits);
    const std::uint32_t biased = (bits >> 23) & 0xffu, fraction = bits & 0x7fffffu;
    // Subnormals (biased exponent 0) have no hidden bit and the exponent of the smallest normals.
    // Non-finite inputs (biased 255) decode to large finite values: never out of range, never UB.
    return biased == 0 ? FloatParts{fraction, -149, (bits >> 31) != 0}
                       : FloatParts{fraction | 0x800000u, static_cast<int>(biased) - 150, (bits >> 31) != 0};
}

/// @brief An exact sum of products of two or three floats, as a fixed-point integer in units of
/// 2^-447 (the smallest product of three floats), in 28 signed 64-bit limbs of 32 bits each whose
/// carries are propagated only when the sign is read.
///
/// Ranges: a product of three floats is below 2^72 * 2^312 = 2^384, so its bits lie at positions
/// 0 .. 830 of the integer; a sum of at most 2^10 of them stays below bit 841, inside the 27th limb
/// (bits 832 .. 863), and the 28th only ever takes carries. Each add_bits call puts less than 2^48
/// into a limb, so a limb absorbs 2^15 calls before its 64 bits could overflow; a 3x3 determinant
/// makes 96.
class ExactSum {
public:
    static constexpr int k_limbs = 28;
    static constexpr int k_lowest_exponent = -447; ///< 3 * -149: the unit of the integer

    KDET_HD ExactSum() {}

    /// @brief Adds (or subtracts) x * y exactly.
    KDET_HD void add_product(float x_value, float y_value, bool subtract) {
        const FloatParts x = float_parts(x_value), y = float_parts(y_value);
        const std::uint64_t m = static_cast<std::uint64_t>(x.m) * y.m; // < 2^48, exact
        add_bits(m, x.e + y.e - k_lowest_exponent, subtract != (x.negative != y.negative));
    }

    /// @brief Adds (or subtracts) x * y * z exactly: the 72-bit significand goes in as two 48-bit halves.
    KDET_HD void add_product(float x_value, float y_value, float z_value, bool subtract) {
        const FloatParts x = float_parts(x_value), y = float_parts(y_value), z = float_parts(z_value);
        const std::uint64_t xy = static_cast<std::uint64_t>(x.m) * y.m; // < 2^48
        const bool negative = subtract != (x.negative != (y.negative != z.negative));
        const int offset = x.e + y.e + z.e - k_lowest_exponent;
        add_bits((xy >> 24) * z.m, offset + 24, negative); // (xy >> 24) < 2^24: product < 2^48
        add_bits((xy & 0xffffffu) * z.m, offset, negative);
    }

    /// @brief -1, 0 or +1: the sign of the exact sum. Propagates the carries through the limbs that
    /// were added to (the value is unchanged).
    KDET_HD int sign() {
        if (highest_ < lowest_) return 0; // nothing added
        KDET_NO_UNROLL
        for (int k = lowest_; k < highest_; ++k) {
            // Keep the limb's residue modulo 2^32 in [0, 2^32) and move the rest (a multiple of 2^32,
            // so the division is exact) into the next limb.
            const std::int64_t low = static_cast<std::int64_t>(static_cast<std::uint64_t>(limb_[k]) & 0xffffffffu);
            limb_[k + 1] += (limb_[k] - low) / (std::int64_t{1} << 32);
            limb_[k] = low;
        }
        // The limbs below `highest_` are now non-negative and together below one unit of it.
        if (limb_[highest_] != 0) return limb_[highest_] > 0 ? 1 : -1;
        KDET_NO_UNROLL
        for (int k = highest_ - 1; k >= lowest_; --k)
            if (limb_[k] != 0) return 1;
        return 0;
    }

private:
    /// @brief Adds +-value * 2^offset, value < 2^48, 0 <= offset < 32 * (k_limbs - 2).
    KDET_HD void add_bits(std::uint64_t value, int offset, bool negative) {
        if (value == 0) return;
        const int k = offset >> 5, shift = offset & 31;
        const std::uint64_t low = (value & 0xffffffffu) << shift; // < 2^63
        const std::uint64_t high = (value >> 32) << shift;        // < 2^47, in units of limb k + 1
        const auto to_limb_k = static_cast<std::int64_t>(low & 0xffffffffu);
        const auto to_limb_k1 = static_cast<std::int64_t>((low >> 32) + high);
        widen_to(k);
        limb_[k] += negative ? -to_limb_k : to_limb_k;
        limb_[k + 1] += negative ? -to_limb_k1 : to_limb_k1;
    }

    /// @brief Makes limbs k and k + 1 part of the range in use, clearing the limbs that join it: only
    /// the limbs a sum touches are ever written or read.
    KDET_HD void widen_to(int k) {
        if (highest_ < lowest_) {
            lowest_ = highest_ = k;
            limb_[k] = 0;
        }
        while (lowest_ > k) limb_[--lowest_] = 0;
        while (highest_ < k + 1) limb_[++highest_] = 0;
    }

    std::int64_t limb_[k_limbs];
    int lowest_ = 1, highest_ = 0; ///< the limbs in use, lowest_ .. highest_ (none at first)
};

/// @brief Adds (subtract: subtracts) the 2x2 determinant (p1 - p0)_u (q1 - q0)_v - (p1 - p0)_v (q1 - q0)_u
/// in the coordinates u and v (0, 1, 2), p and q given as their two points: 8 products of two floats.
KDET_HD inline void add_det2(ExactSum& sum, const vec3 p[2], const vec3 q[2], int u, int v, bool subtract) {
    KDET_NO_UNROLL
    for (int i = 0; i < 2; ++i)
        KDET_NO_UNROLL
        for (int j = 0; j < 2; ++j) {
            // Point 0 of a difference enters with a minus sign: the term's sign flips once per point 0.
            const bool flip = ((i == 0) != (j == 0)) != subtract;
            sum.add_product(component(p[i], u), component(q[j], v), flip);
            sum.add_product(component(p[i], v), component(q[j], u), !flip);
        }
}

/// @brief Exact sign of the 2x2 determinant of p1 - p0 and q1 - q0 in the coordinates u and v.
KDET_HD inline int sign_det2_exact(vec3 p0, vec3 p1, vec3 q0, vec3 q1, int u, int v) {
    const vec3 p[2] = {p0, p1}, q[2] = {q0, q1};
    ExactSum sum;
    add_det2(sum, p, q, u, v, false);
    return sum.sign();
}

/// @brief The coordinate in which the difference to - from is non-zero when it is the only one; -1
/// when two or more are; 3 when none is.
KDET_HD inline int single_coordinate(const vec3 points[2]) {
    const bool x = points[0].x != points[1].x, y = points[0].y != points[1].y, z = points[0].z != points[1].z;
    return int{x} + int{y} + int{z} > 1 ? -1 : (x ? 0 : (y ? 1 : (z ? 2 : 3)));
}

/// @brief Exact sign of det(p1 - p0, q1 - q0, r1 - r0) (rows): 48 products of three floats, or 8
/// products of two when a row has a single non-zero coordinate c (det(p, q, r) = r_c (p x q)_c, the
/// rows rotated as needed), which is common in meshes moved along a coordinate axis.
KDET_HD inline int sign_det3_exact(vec3 p0, vec3 p1, vec3 q0, vec3 q1, vec3 r0, vec3 r1) {
    const vec3 p[2] = {p0, p1}, q[2] = {q0, q1}, r[2] = {r0, r1};
    const vec3* rows[3] = {p, q, r};
    ExactSum sum;
    KDET_NO_UNROLL
    for (int row = 2; row >= 0; --row) {
        const int c = single_coordinate(rows[row]);
        if (c == 3) return 0;
        if (c < 0) continue;
        const bool falling = component(rows[row][1], c) < component(rows[row][0], c);
        add_det2(sum, rows[(row + 1) % 3], rows[(row + 2) % 3], (c + 1) % 3, (c + 2) % 3, falling);
        return sum.sign();
    }
    KDET_NO_UNROLL
    for (int s = 0; s < 6; ++s) {
        // The permutations (a, b, c) of (x, y, z): cyclic ones for s < 3, the odd ones subtracted. A term
        // with a zero difference (equal coordinates, common in meshes moved along an axis) adds nothing.
        const int a = s % 3, b = (a + (s < 3 ? 1 : 2)) % 3, c = 3 - a - b;
        if (component(p0, a) == component(p1, a) || component(q0, b) == component(q1, b) ||
            component(r0, c) == component(r1, c))
            continue;
        KDET_NO_UNROLL
        for (int i = 0; i < 2; ++i)
            KDET_NO_UNROLL
            for (int j = 0; j < 2; ++j)
                KDET_NO_UNROLL
                for (int k = 0; k < 2; ++k) {
                    const bool flip = ((i == 0) != (j == 0)) != (k == 0);
                    sum.add_product(component(p[i], a), component(q[j], b), component(r[k], c), flip != (s >= 3));
                }
    }
    return sum.sign();
}

} // namespace kdet::exact
