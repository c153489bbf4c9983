#!/usr/bin/env bash
# Registers and stack bytes per thread of every CUDA kernel, as ptxas reports them: needs nvcc, not
# a GPU. Compiles the CUDA backend's translation unit once more, for one architecture, with the
# flags of a configured build folder.
#   scripts/kernel-resources.sh [BUILD_DIR] [ARCH]      (defaults: build, 90)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
arch=${2:-90}
[[ -f "$build/CMakeCache.txt" ]] || { echo "kernel-resources: $build is not a configured build folder" >&2; exit 2; }
cmake -S . -B "$build" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON >/dev/null
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 - "$build" "$arch" "$work" <<'EOF'
import json, re, shlex, subprocess, sys
build, arch, work = sys.argv[1:]
entries = [e for e in json.load(open(f"{build}/compile_commands.json")) if e["file"].endswith("cuda_pipeline.cu")]
if not entries:
    sys.exit("kernel-resources: the build folder has no CUDA backend (configure with KDET_ENABLE_CUDA=ON)")
args = shlex.split(entries[0]["command"])
kept, skip = [], False
for a in args:
    if skip:
        skip = False
        continue
    if a in ("-o", "-MF", "-MT"):
        skip = True
        continue
    if a == "-MD" or a.startswith("--generate-code") or a.startswith("-gencode") or a.startswith("-Werror"):
        continue
    kept.append(a)
kept += [f"--generate-code=arch=compute_{arch},code=sm_{arch}", "-Xptxas", "-v", "-o", f"{work}/tu.o"]
run = subprocess.run(kept, cwd=entries[0]["directory"], capture_output=True, text=True)
if run.returncode:
    sys.exit(run.stderr)
rows, name, stack = [], None, "?"
for line in run.stderr.splitlines():
    m = re.search(r"Compiling entry function '(\S+)'", line)
    if m:
        plain = subprocess.run(["c++filt", m.group(1)], capture_output=True, text=True).stdout.strip()
        k = re.search(r"for_each(?:_counted)?_kernel<kdet::(\w+)(?:<\(kdet::NarrowPhase\)(\d+)((?:, \w+)*)>)?", plain)
        tests = ["sat", "sat_no_edges", "sat_mtv", "gjk", "fast", "exact"]  # kdet::NarrowPhase's order
        # CUB's own kernels are left out; a kernel per narrow-phase test is named with its test, and the
        # narrow phase that runs the face planes (NarrowPhaseKernel's last argument) with ", planes".
        planes = ", planes" if k and k.group(1) == "NarrowPhaseKernel" and (k.group(3) or "").endswith("true") else ""
        name = (k.group(1) + (f"<{tests[int(k.group(2))]}{planes}>" if k.group(2) else "")) if k else None
    m = re.search(r"(\d+) bytes stack frame", line)
    if m:
        stack = m.group(1)
    m = re.search(r"Used (\d+) registers", line)
    if m and name:
        rows.append((name, int(m.group(1)), int(stack)))
        name = None
print(f"sm_{arch}: per thread")
print(f"{'kernel':40s} {'registers':>9s} {'stack bytes':>11s}")
for n, r, s in sorted(rows):
    print(f"{n:40s} {r:9d} {s:11d}")
EOF
