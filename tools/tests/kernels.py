"""The numerical kernels another x86-64 machine may pick, as the
environment variables that force them on this one (docs/testing.md, "On
any machine"):
- OpenBLAS (numpy's and scipy's linear algebra): the AVX2 kernel where
  this CPU has AVX-512 (as a CPU without it runs), else SSE3's, the plainest;
- numpy's own SIMD loops: without the AVX-512 ones this CPU has;
- glibc's libm (Python's math, the simulators' physics): without FMA, AVX2
  and AVX-512, so exp, log, pow and sin take their SSE2 paths.
Each takes effect in a process started with it. `python -m tests.kernels`
prints them, one VAR=VALUE a line (scripts/other_kernels.sh)."""
import platform


def _cpu_flags() -> set:
    try:
        with open("/proc/cpuinfo") as f:
            return next((set(l.split(":", 1)[1].split()) for l in f if l.startswith("flags")), set())
    except OSError:
        return set()


def other_kernels() -> dict:
    """{variable: value}; empty where this is no x86-64 machine (the names
    are x86's)."""
    if platform.machine() != "x86_64":
        return {}
    from numpy._core._multiarray_umath import __cpu_features__ as numpy_features
    env = {"OPENBLAS_CORETYPE": "Haswell" if "avx512f" in _cpu_flags() else "Prescott",
           "GLIBC_TUNABLES": "glibc.cpu.hwcaps=-AVX512F,-AVX2,-FMA"}
    avx512 = sorted(k for k, on in numpy_features.items() if on and k.startswith("AVX512"))
    if avx512:
        env["NPY_DISABLE_CPU_FEATURES"] = ",".join(avx512)
    return env


if __name__ == "__main__":
    for name, value in other_kernels().items():
        print(f"{name}={value}")
