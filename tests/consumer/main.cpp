// A program built against kdet from outside its source tree (tests/consumer/run.sh). It makes two small
// tet meshes, writes them, finds their colliding pairs with the one-off call and with a Detector over
// two frames, and writes the pairs, so that run.sh can compare them with `kdet collide` on the same files.
#include <kdet/kdet.hpp>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace {

/// A box of n x n x n unit cubes starting at `origin`, each cube split into six tets around its diagonal.
kdet::TetMesh cube_grid(int n, double origin_x, double origin_y, double origin_z) {
    kdet::TetMesh mesh;
    const auto id = [n](int i, int j, int k) { return static_cast<std::uint32_t>((k * (n + 1) + j) * (n + 1) + i); };
    for (int k = 0; k <= n; ++k)
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i) mesh.positions.insert(mesh.positions.end(), {origin_x + i, origin_y + j, origin_z + k});
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const std::uint32_t c[8] = {id(i, j, k),         id(i + 1, j, k),         id(i, j + 1, k),
                                            id(i + 1, j + 1, k), id(i, j, k + 1),         id(i + 1, j, k + 1),
                                            id(i, j + 1, k + 1), id(i + 1, j + 1, k + 1)};
                // Corner bits: 1 = +x, 2 = +y, 4 = +z. Each tet walks from corner 0 to 7 along two axes.
                const int axes[6][2] = {{1, 2}, {1, 4}, {2, 1}, {2, 4}, {4, 1}, {4, 2}};
                for (const auto& p : axes) mesh.tets.insert(mesh.tets.end(), {c[0], c[p[0]], c[p[0] | p[1]], c[7]});
            }
    return mesh;
}

} // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::cerr << "usage: consumer OUT_DIR  (writes a.mesh, b.mesh and pairs.txt there)\n";
        return 2;
    }
    const std::string out = argv[1];
    try {
        const kdet::TetMesh a = cube_grid(3, 0.0, 0.0, 0.0);
        const kdet::TetMesh b = cube_grid(2, 1.5, 1.25, 2.125);
        kdet::write_tet_mesh(a, out + "/a.mesh");
        kdet::write_tet_mesh(b, out + "/b.mesh");
        const auto pairs = kdet::collide(kdet::read_tet_mesh(out + "/a.mesh"), kdet::read_tet_mesh(out + "/b.mesh"));

        // The same pairs from a Detector: B starts far away, then moves to where it was written.
        kdet::DetectorOptions options;
        if (!kdet::parse("brute-force-pairs", options.method)) throw kdet::Error("option table lost a method");
        kdet::Detector detector(options);
        detector.add_object(a);
        const kdet::ObjectId moving = detector.add_object(b);
        std::vector<double> far = b.positions;
        for (std::size_t v = 0; v < far.size(); v += 3) far[v] += 100.0;
        detector.set_positions(moving, far.data(), b.num_vertices());
        const std::size_t far_pairs = detector.detect().pairs.size();
        detector.set_positions(moving, b.positions.data(), b.num_vertices());
        const kdet::FrameResult& frame = detector.detect();
        bool same = far_pairs == 0 && frame.pairs.size() == pairs.size();
        for (std::size_t k = 0; same && k < pairs.size(); ++k)
            same = frame.pairs[k].tet_a == pairs[k].first && frame.pairs[k].tet_b == pairs[k].second;

        std::ofstream file(out + "/pairs.txt");
        for (const auto& [i, j] : pairs) file << i << ' ' << j << '\n';
        std::printf("kdet %s: %zu pairs between %zu and %zu tets; detector frames %s\n", kdet::version().c_str(),
                    pairs.size(), a.num_tets(), b.num_tets(), same ? "agree" : "DISAGREE");
        return same && file ? 0 : 1;
    } catch (const kdet::Error& error) {
        std::fprintf(stderr, "consumer: %s\n", error.what());
        return 1;
    }
}
