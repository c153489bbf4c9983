#pragma once
/// @file peer.hpp
/// @brief The peer kdet is compared with (cpu_vs_cgal.cpp): what a CPU user would write without kdet.

#include "geometry/tet_intersect.hpp"

#include <kdet/detector.hpp>
#include <kdet/mesh.hpp>

#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace kdet::bench {

/// The peer: CGAL's box intersection, then sat on every box-overlapping pair, lower caller id first.
class Peer {
public:
    using Box = CGAL::Box_intersection_d::Box_with_info_d<float, 3, std::uint32_t>;

    /// Pairs (i in a, j in b), or (i < j) inside objects[0] when self is set; sorted.
    std::vector<IndexPair> collide(const std::vector<TetMesh>& objects, bool self) {
        pairs_.clear();
        load(objects);
        if (self) {
            CGAL::box_self_intersection_d(boxes_[0].begin(), boxes_[0].end(), [this](const Box& x, const Box& y) {
                const std::uint32_t i = std::min(x.info(), y.info()), j = std::max(x.info(), y.info());
                if (!share_vertex(0, i, 0, j) && tets_intersect_sat(tets_[0][i].v, tets_[0][j].v)) pairs_.emplace_back(i, j);
            });
        } else {
            CGAL::box_intersection_d(boxes_[0].begin(), boxes_[0].end(), boxes_[1].begin(), boxes_[1].end(),
                                     [this](const Box& x, const Box& y) {
                                         if (tets_intersect_sat(tets_[0][x.info()].v, tets_[1][y.info()].v))
                                             pairs_.emplace_back(x.info(), y.info());
                                     });
        }
        std::sort(pairs_.begin(), pairs_.end());
        return pairs_;
    }

private:
    struct Tet {
        vec3 v[4];
    };

    void load(const std::vector<TetMesh>& objects) {
        meshes_ = &objects;
        tets_.resize(objects.size());
        boxes_.resize(objects.size());
        for (std::size_t o = 0; o < objects.size(); ++o) {
            const TetMesh& mesh = objects[o];
            tets_[o].resize(mesh.num_tets());
            boxes_[o].clear();
            boxes_[o].reserve(mesh.num_tets());
            for (std::size_t t = 0; t < mesh.num_tets(); ++t) {
                Tet& tet = tets_[o][t];
                for (int k = 0; k < 4; ++k) {
                    const double* p = &mesh.positions[3 * mesh.tets[4 * t + k]];
                    tet.v[k] = make_vec3(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]));
                }
                const Aabb b = tet_box(tet.v);
                float lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
                boxes_[o].emplace_back(lo, hi, static_cast<std::uint32_t>(t));
            }
        }
    }

    bool share_vertex(std::size_t oa, std::uint32_t i, std::size_t ob, std::uint32_t j) const {
        const std::uint32_t* a = &(*meshes_)[oa].tets[4 * i];
        const std::uint32_t* b = &(*meshes_)[ob].tets[4 * j];
        for (int p = 0; p < 4; ++p)
            for (int q = 0; q < 4; ++q)
                if (a[p] == b[q]) return true;
        return false;
    }

    const std::vector<TetMesh>* meshes_ = nullptr;
    std::vector<std::vector<Tet>> tets_;
    std::vector<std::vector<Box>> boxes_;
    std::vector<IndexPair> pairs_;
};

} // namespace kdet::bench
