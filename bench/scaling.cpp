/// Time per frame against tet count for the built-in procedural scene, to show linear growth.
/// Each benchmark detects on the frame of deepest interpenetration, after one untimed detection that
/// sizes the buffers and faults their memory in, as a simulation's later frames find them.

#include <kdet/detector.hpp>
#include <kdet/scenes.hpp>

#include <benchmark/benchmark.h>

#include <vector>

namespace {

void bench_procedural(benchmark::State& state) {
    const auto tets = static_cast<std::size_t>(state.range(0));
    const bool self = state.range(1) != 0;
    kdet::ProceduralSceneOptions scene_options;
    scene_options.total_tets = tets;
    const kdet::ProceduralScene scene(scene_options);
    kdet::Detector detector;
    std::vector<float> xyz;
    const int frame = scene.num_frames() / 2;
    for (std::size_t o = 0; o < scene.num_objects(); ++o) {
        const kdet::ObjectId id = detector.add_object(scene.rest_mesh(o));
        detector.set_self_collision(id, self);
        scene.positions(o, frame, xyz);
        detector.set_positions(id, xyz.data(), xyz.size() / 3);
    }
    std::uint64_t pairs = detector.detect().counts.colliding_pairs;
    for (auto _ : state) {
        const kdet::FrameResult& result = detector.detect();
        pairs = result.counts.colliding_pairs;
        benchmark::DoNotOptimize(pairs);
    }
    state.counters["tets"] = static_cast<double>(tets);
    state.counters["pairs"] = static_cast<double>(pairs);
    state.counters["ns_per_tet"] = benchmark::Counter(static_cast<double>(tets) * static_cast<double>(state.iterations()),
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.counters["memory_MiB"] = static_cast<double>(detector.memory_bytes()) / (1024.0 * 1024.0);
}

} // namespace

BENCHMARK(bench_procedural)
    ->ArgsProduct({{10000, 30000, 100000, 300000, 1000000}, {0, 1}})
    ->ArgNames({"tets", "self"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_MAIN();
