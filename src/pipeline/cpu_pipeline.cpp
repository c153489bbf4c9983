#include "exec/cpu_exec.hpp"
#include "pipeline/pipeline.hpp"

namespace kdet {

std::unique_ptr<PipelineBase> make_cpu_pipeline(const DetectorOptions& options) {
    return std::make_unique<Pipeline<CpuExec>>(options);
}

} // namespace kdet
