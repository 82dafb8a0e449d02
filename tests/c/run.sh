#!/usr/bin/env bash
# The C API's tests: the header compiles alone as C99 and C++; tests/c/test_api.c (life
# cycle, error paths, cancellation, threads, versions) runs whole plain and under
# AddressSanitizer + UndefinedBehaviorSanitizer (LeakSanitizer on), and its ownership tests
# under valgrind (no definite leaks, no errors; see below); the C++ wrapper test, the example
# program and the README's C example run on generated shapes.
# Needs target/release/libshapecorr.so (tests/run_all.sh builds it first).
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
lib_dir=$root/target/release
out=$root/target/c-tests
mkdir -p "$out"
[ -f "$lib_dir/libshapecorr.so" ] || { echo "build the library first: cargo build --release"; exit 1; }
version=$(sed -n 's/^version = "\(.*\)"$/\1/p' Cargo.toml | head -n 1)
warn=(-Wall -Wextra -Wpedantic -Werror)
link=(-L"$lib_dir" -lshapecorr -Wl,-rpath,"$lib_dir" -lpthread -lm)
cc=${CC:-gcc}
cxx=${CXX:-g++}

echo "== header alone: C99, C11 and C++17"
printf '#include "shapecorr.h"\nint main(void) { return sc_abi_version() == SC_ABI_VERSION ? 0 : 1; }\n' > "$out/header_only.c"
for std in c99 c11; do
    "$cc" -std=$std "${warn[@]}" -Iinclude "$out/header_only.c" "${link[@]}" -o "$out/header_$std"
    "$out/header_$std"
done
cp "$out/header_only.c" "$out/header_only.cpp"
"$cxx" -std=c++17 "${warn[@]}" -Iinclude "$out/header_only.cpp" "${link[@]}" -o "$out/header_cpp"
"$out/header_cpp"

echo "== test_api (plain)"
"$cc" -std=c99 "${warn[@]}" -O1 -g -Iinclude -DCARGO_VERSION="\"$version\"" \
    tests/c/test_api.c "${link[@]}" -o "$out/test_api"
"$out/test_api"

echo "== test_api (AddressSanitizer + UndefinedBehaviorSanitizer)"
"$cc" -std=c99 "${warn[@]}" -O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer \
    -fno-sanitize-recover=all -Iinclude -DCARGO_VERSION="\"$version\"" \
    tests/c/test_api.c "${link[@]}" -o "$out/test_api_asan"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1 \
    "$out/test_api_asan"

echo "== test_api (valgrind, quick sizes): the ownership tests"
if ! command -v valgrind >/dev/null; then
    echo "installing valgrind"
    apt-get install -y -qq valgrind >/dev/null || { sudo apt-get update -qq && sudo apt-get install -y -qq valgrind >/dev/null; }
fi
# valgrind checks every access of the library's own (uninstrumented) code, which ASan does
# not: it runs every test that hands memory across the API once, each handle's whole life
# cycle and every getter into a caller's buffer (correspondence, symmetry, pointwise map,
# surface map, batch), the error paths, a cancel in each kind of job, and calls from several
# threads. It skips four tests that only run sc_match again, with no API call of their own
# (point_cloud, unverified_has_no_confidence, working, whose accessor life_cycle runs, and
# cancellation, which cancels at each stage): they run whole plain and under
# ASan+UBSan+LSan above (a sixth of valgrind's time).
ownership=(version status_text options option_extremes shape_errors repairs match_errors
    resource_limits life_cycle cancel_huge_restarts symmetry pointwise_options pointwise_errors
    pointwise_permuted_copy pointwise_cancellation transfer handles_in_use surface_map_shapes batch
    landmarks_and_other_answer landmark_errors)
# --fair-sched: valgrind runs one thread at a time; fair turns keep the caller's thread,
# which delivers a cancel, from waiting behind the workers. Since it runs one thread at a
# time, the threads test (half the time) runs in a second valgrind beside the others: one
# process a core.
valgrind=(valgrind -q --fair-sched=yes --leak-check=full --errors-for-leak-kinds=definite
    --show-leak-kinds=definite --error-exitcode=99)
SHAPECORR_TEST_QUICK=1 "${valgrind[@]}" "$out/test_api" concurrency >"$out/valgrind_threads.log" 2>&1 &
threads=$!
status=0
SHAPECORR_TEST_QUICK=1 "${valgrind[@]}" "$out/test_api" "${ownership[@]}" || status=$?
wait $threads || status=$?
cat "$out/valgrind_threads.log"
[ $status -eq 0 ] || { echo "test_api under valgrind failed ($status)"; exit 1; }

echo "== C++ wrapper"
"$cxx" -std=c++17 "${warn[@]}" -O1 -Iinclude tests/c/test_cpp.cpp "${link[@]}" -o "$out/test_cpp"
"$out/test_cpp"

echo "== example program and the README's C example on two generated figures"
"$lib_dir/shapecorr" synth --kind humanoid --pose 0 --vertices 3000 --out "$out/a.ply" >/dev/null
"$lib_dir/shapecorr" synth --kind humanoid --pose 4 --vertices 3000 --out "$out/b.ply" >/dev/null
"$cc" -std=c99 "${warn[@]}" -Iinclude tests/c/example_match.c "${link[@]}" -o "$out/example_match"
"$out/example_match" "$out/a.ply" "$out/b.ply" | tee "$out/example.txt"
grep -q "one-to-one matches" "$out/example.txt"
if "$out/example_match" "$out/a.ply" /nonexistent.ply 2>"$out/example_err.txt"; then
    echo "example_match accepted a missing file"; exit 1
fi
grep -q "nonexistent.ply" "$out/example_err.txt"
# The ```c block after the marker in README.md, compiled and run as written.
awk '/<!-- readme-c-example -->/{m=1; next} m && /^```c/{p=1; next} p && /^```/{exit} p' \
    README.md > "$out/readme_example.c"
[ -s "$out/readme_example.c" ] || { echo "README has no C example after the marker"; exit 1; }
"$cc" -std=c99 "${warn[@]}" -Iinclude "$out/readme_example.c" "${link[@]}" -o "$out/readme_example"
(cd "$out" && ./readme_example a.ply b.ply) | tee "$out/readme_example.txt"
[ -s "$out/readme_example.txt" ]
echo "== under an address-space limit (ulimit -v): 5K-vertex figures run under 1 GB, and"
echo "   under 300 MB return SC_STATUS_RESOURCE_LIMIT, never abort (plain build: ASan and"
echo "   valgrind reserve more address space than these limits)"
"$lib_dir/shapecorr" synth --kind humanoid --pose 0 --vertices 5000 --out "$out/a5.ply" >/dev/null
"$lib_dir/shapecorr" synth --kind humanoid --pose 3 --vertices 5000 --out "$out/b5.ply" >/dev/null
"$cc" -std=c99 "${warn[@]}" -O1 -g -Iinclude tests/c/memory_cap.c "${link[@]}" -o "$out/memory_cap"
(ulimit -v 1048576 && RAYON_NUM_THREADS=2 "$out/memory_cap" "$out/a5.ply" "$out/b5.ply" ok)
(ulimit -v 307200 && RAYON_NUM_THREADS=2 "$out/memory_cap" "$out/a5.ply" "$out/b5.ply" limit)
echo "C tests passed"
