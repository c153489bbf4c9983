#include "exec/cuda_exec.cuh"
#include "pipeline/baselines.hpp"

namespace kdet {

std::unique_ptr<PipelineBase> make_cuda_pipeline(const DetectorOptions& options) {
    return make_pipeline<CudaExec>(options);
}

bool cuda_available(std::string* reason) {
    int devices = 0;
    const cudaError_t status = cudaGetDeviceCount(&devices);
    if (status == cudaSuccess && devices > 0) return true;
    if (reason)
        *reason = status != cudaSuccess ? std::string("no usable CUDA device: ") + cudaGetErrorString(status)
                                        : "no CUDA device found";
    return false;
}

} // namespace kdet
