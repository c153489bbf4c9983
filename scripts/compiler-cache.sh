# Sourced by the scripts that build the library more than once (test.sh, setup-and-run.sh): when ccache is
# installed (install-deps.sh installs it), CMake puts it in front of the compilers of every new build
# folder, so the later builds of the same sources with the same flags (the Python package, the consumer's
# add_subdirectory) reuse build/'s objects instead of compiling them again. ccache keys on the compiler's
# name too, and pip's build picks g++ where a plain CMake build picks c++, so every build is told g++.
# What the caller sets wins.
if command -v ccache >/dev/null; then
  export CMAKE_CXX_COMPILER_LAUNCHER="${CMAKE_CXX_COMPILER_LAUNCHER:-ccache}"
  export CMAKE_CUDA_COMPILER_LAUNCHER="${CMAKE_CUDA_COMPILER_LAUNCHER:-ccache}"
  export CXX="${CXX:-g++}"
fi
