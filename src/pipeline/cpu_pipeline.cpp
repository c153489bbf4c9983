#include "exec/cpu_exec.hpp"
#include "pipeline/baselines.hpp"

#include <atomic>

namespace kdet {

namespace {
std::atomic<PipelineFactory> cpu_pipeline_factory{nullptr};
} // namespace

std::unique_ptr<PipelineBase> make_cpu_pipeline(const DetectorOptions& options) {
    if (const PipelineFactory factory = cpu_pipeline_factory.load()) return factory(options);
    return make_pipeline<CpuExec>(options);
}

void set_cpu_pipeline_factory(PipelineFactory factory) { cpu_pipeline_factory.store(factory); }

} // namespace kdet
