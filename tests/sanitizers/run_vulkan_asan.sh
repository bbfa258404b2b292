#!/usr/bin/env bash
# Runs every Vulkan test executable of an ASan + UBSan build (MMVK_SANITIZE)
# with leak checking on. The Vulkan driver (lavapipe) and the validation
# layer are preloaded, after the ASan runtime (which must come first), so
# that the loader's dlclose does not unmap them and their own leaks can be
# suppressed by name (tests/sanitizers/lsan.supp). Exits non-zero on the
# first failing executable.
#   tests/sanitizers/run_vulkan_asan.sh build-asan
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build-asan}
libdir=/usr/lib/x86_64-linux-gnu
preload="$(gcc -print-file-name=libasan.so)"
for lib in libvulkan_lvp.so libVkLayer_khronos_validation.so; do
  [ -f "$libdir/$lib" ] && preload="$preload $libdir/$lib"
done
status=0
ran=0
for test in "$build"/tests/mmvk_test_vulkan_*; do
  [ -x "$test" ] || continue
  ran=$((ran + 1))
  start=$(date +%s)
  if LD_PRELOAD="$preload" ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
     LSAN_OPTIONS="suppressions=$PWD/tests/sanitizers/lsan.supp:print_suppressions=0" \
     "$test" --gtest_brief=1 >"$test.asan.log" 2>&1; then
    echo "ok   $(basename "$test") ($(( $(date +%s) - start )) s)"
  else
    echo "FAIL $(basename "$test") ($(( $(date +%s) - start )) s), log: $test.asan.log"
    tail -n 40 "$test.asan.log"
    status=1
  fi
done
[ "$ran" -gt 0 ] || { echo "no Vulkan test executable in $build/tests (built with MMVK_BUILD_VULKAN?)"; exit 1; }
exit $status
