#include "exec/cpu_exec.hpp"
#include "pipeline/baselines.hpp"

namespace kdet {

std::unique_ptr<PipelineBase> make_cpu_pipeline(const DetectorOptions& options) {
    return make_pipeline<CpuExec>(options);
}

} // namespace kdet
