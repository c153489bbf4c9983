#include "pipeline/pipeline_base.hpp"

#include <kdet/error.hpp>

// Built only without the CUDA backend: asking for it is a clear error, never a silent CPU fallback.
#if !defined(KDET_HAS_CUDA)
namespace kdet {

std::unique_ptr<PipelineBase> make_cuda_pipeline(const DetectorOptions&) {
    throw Error("backend 'cuda' is not available: kdet was built without CUDA (configure with -DKDET_ENABLE_CUDA=ON "
                "on a machine with nvcc)");
}

bool cuda_available(std::string* reason) {
    if (reason) *reason = "kdet was built without CUDA";
    return false;
}

} // namespace kdet
#endif
