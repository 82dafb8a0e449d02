#!/usr/bin/env bash
# The C/C++ install, tested as a user meets it (docs/decisions.md, "Native install: cargo-c"):
# - `cargo cinstall` (cargo-c, installed here if missing) into a staging folder (--prefix +
#   --destdir) and into a temporary prefix;
# - the installed library's soname, the header's SC_ABI_VERSION and sc_abi_version() agree;
#   the library is stripped and at most 8 MB;
# - the README's C and C++ examples are built from the install twice, with
#   `pkg-config --cflags --libs shapecorr` and as a CMake project with
#   `find_package(shapecorr CONFIG REQUIRED)` (cmake from Debian if missing), and run on two
#   generated figures; CMake refuses a version request the install does not satisfy.
# Needs target/release/shapecorr (tests/run_all.sh builds it) for the figures.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
out=$root/target/install-tests
rm -rf "$out"
mkdir -p "$out"
warn=(-Wall -Wextra -Wpedantic -Werror)

# cargo-c's last release that builds with this toolchain (0.10.26 needs rustc 1.97). No
# registry has a prebuilt one that recent (Debian's is 0.9), so it is compiled, unoptimised
# (opt-level 0, 256 codegen units, no LTO, no debug information): it only drives cargo, and
# its build takes half the CPU time of the opt-level 1 build (344 s against 657 s measured).
cargo_c_version=0.10.24+cargo-0.98.0
if ! cargo cinstall --version 2>/dev/null | grep -q "${cargo_c_version%%+*}"; then
    echo "== installing cargo-c $cargo_c_version (a few minutes, once)"
    CARGO_PROFILE_RELEASE_LTO=off CARGO_PROFILE_RELEASE_OPT_LEVEL=0 \
        CARGO_PROFILE_RELEASE_CODEGEN_UNITS=256 CARGO_PROFILE_RELEASE_DEBUG=0 \
        cargo install --locked --quiet cargo-c --version "$cargo_c_version"
fi
for tool in cmake pkg-config; do
    if ! command -v $tool >/dev/null; then
        echo "installing $tool"
        apt-get install -y -qq $tool >/dev/null ||
            { apt-get update -qq && apt-get install -y -qq $tool >/dev/null; }
    fi
done

echo "== cargo cinstall: staged (--prefix /opt/shapecorr --destdir), then into a prefix"
# The staged install keeps cargo-c's default library folder (lib/<multiarch> on Debian); the
# prefix uses plain lib.
install=(cargo cinstall --locked --profile dist -p shapecorr)
"${install[@]}" --prefix /opt/shapecorr --destdir "$out/stage"
prefix=$out/prefix
"${install[@]}" --prefix "$prefix" --libdir lib
stage=$out/stage/opt/shapecorr
staged_pc=$(find "$stage/lib" -name shapecorr.pc)
grep -qx "prefix=/opt/shapecorr" "$staged_pc" ||
    { echo "the staged shapecorr.pc does not name /opt/shapecorr"; exit 1; }
for file in include/shapecorr.h include/shapecorr.hpp lib/pkgconfig/shapecorr.pc \
    share/cmake/shapecorr/shapecorrConfig.cmake \
    share/cmake/shapecorr/shapecorrConfigVersion.cmake; do
    [ -f "$prefix/$file" ] || { echo "missing $prefix/$file"; exit 1; }
    [ -f "$stage/$file" ] || [[ $file == lib/* ]] || { echo "missing $stage/$file"; exit 1; }
done

echo "== soname, header and sc_abi_version() agree; stripped, at most 8 MB"
abi=$(sed -n 's/^#define SC_ABI_VERSION \([0-9]*\)$/\1/p' "$prefix/include/shapecorr.h")
[ -n "$abi" ] || { echo "no SC_ABI_VERSION in the installed header"; exit 1; }
[ -L "$prefix/lib/libshapecorr.so" ] && [ -L "$prefix/lib/libshapecorr.so.$abi" ] ||
    { echo "libshapecorr.so and libshapecorr.so.$abi must be links"; ls -l "$prefix/lib"; exit 1; }
library=$(readlink -f "$prefix/lib/libshapecorr.so")
soname=$(readelf -d "$library" | sed -n 's/.*Library soname: \[\(.*\)\]/\1/p')
[ "$soname" = "libshapecorr.so.$abi" ] ||
    { echo "soname '$soname', header SC_ABI_VERSION $abi"; exit 1; }
if readelf -S "$library" | grep -qE '\.symtab|\.debug_'; then
    echo "the installed library is not stripped"; exit 1
fi
size=$(stat -c %s "$library")
[ "$size" -le $((8 * 1024 * 1024)) ] || { echo "the installed library is $size bytes (> 8 MB)"; exit 1; }
echo "soname $soname, SC_ABI_VERSION $abi, $(basename "$library") $size bytes, stripped"

# The README's examples, as written (the fenced block after each marker).
readme_block() {
    awk -v marker="<!-- $1 -->" -v fence="^\`\`\`$2" \
        '$0 == marker {m=1; next} m && $0 ~ fence {p=1; next} p && /^```/ {exit} p' README.md
}
mkdir -p "$out/src"
readme_block readme-c-example c > "$out/src/example.c"
readme_block readme-cpp-example cpp > "$out/src/example.cpp"
for f in example.c example.cpp; do
    [ -s "$out/src/$f" ] || { echo "README has no example for $f after its marker"; exit 1; }
done
cat > "$out/src/abi.c" <<'EOF'
#include <stdio.h>
#include "shapecorr.h"
int main(void) {
    printf("%u %u\n", (unsigned)SC_ABI_VERSION, (unsigned)sc_abi_version());
    return sc_abi_version() == SC_ABI_VERSION ? 0 : 1;
}
EOF
figures=$out/figures
mkdir -p "$figures"
target/release/shapecorr synth --kind humanoid --pose 0 --vertices 2000 --out "$figures/a.ply" >/dev/null
target/release/shapecorr synth --kind humanoid --pose 4 --vertices 2000 --out "$figures/b.ply" >/dev/null

# Runs the three programs of one build: the ABI check, then both examples on the figures.
# Each must load the installed library, not the one in target/.
run_programs() {
    local dir=$1
    ldd "$dir/example_c" | grep -q "libshapecorr.so.$abi => $prefix/lib/" ||
        { echo "$dir/example_c does not load the installed library:"; ldd "$dir/example_c"; exit 1; }
    [ "$("$dir/abi")" = "$abi $abi" ] || { echo "sc_abi_version() differs from the header"; exit 1; }
    "$dir/example_c" "$figures/a.ply" "$figures/b.ply" > "$dir/c.txt"
    grep -q "^region [0-9]* of A <-> region [0-9]* of B$" "$dir/c.txt"
    "$dir/example_cpp" "$figures/a.ply" "$figures/b.ply" > "$dir/cpp.txt"
    grep -q "^region [0-9]* of A <-> region [0-9]* of B$" "$dir/cpp.txt"
    # Both examples print the same one-to-one matches (the C++ wrapper adds nothing).
    cmp "$dir/c.txt" <(grep "^region" "$dir/cpp.txt")
}

echo "== pkg-config --cflags --libs shapecorr"
export PKG_CONFIG_PATH=$prefix/lib/pkgconfig
[ "$(pkg-config --modversion shapecorr)" = "$(sed -n 's/^version = "\(.*\)"$/\1/p' Cargo.toml | head -n 1)" ]
read -r -a flags <<< "$(pkg-config --cflags --libs shapecorr)"
rpath=-Wl,-rpath,$(pkg-config --variable=libdir shapecorr)
built=$out/pkg-config
mkdir -p "$built"
cc -std=c99 "${warn[@]}" "$out/src/abi.c" "${flags[@]}" "$rpath" -o "$built/abi"
cc -std=c99 "${warn[@]}" "$out/src/example.c" "${flags[@]}" "$rpath" -o "$built/example_c"
c++ -std=c++17 "${warn[@]}" "$out/src/example.cpp" "${flags[@]}" "$rpath" -o "$built/example_cpp"
run_programs "$built"

echo "== CMake find_package(shapecorr CONFIG REQUIRED)"
cat > "$out/src/CMakeLists.txt" <<'EOF'
cmake_minimum_required(VERSION 3.16)
project(shapecorr_consumer C CXX)
find_package(shapecorr ${WANT_VERSION} CONFIG REQUIRED)
get_target_property(library shapecorr::shapecorr IMPORTED_LOCATION)
message(STATUS "shapecorr library: ${library}")
add_executable(abi abi.c)
add_executable(example_c example.c)
add_executable(example_cpp example.cpp)
set_target_properties(example_cpp PROPERTIES CXX_STANDARD 17 CXX_STANDARD_REQUIRED ON)
foreach(program abi example_c example_cpp)
    target_link_libraries(${program} PRIVATE shapecorr::shapecorr)
endforeach()
EOF
version=$(pkg-config --modversion shapecorr)
cmake -S "$out/src" -B "$out/cmake" -DCMAKE_PREFIX_PATH="$prefix" -DWANT_VERSION="${version%.*}" \
    -DCMAKE_C_FLAGS="${warn[*]}" -DCMAKE_CXX_FLAGS="${warn[*]}" >"$out/cmake.log"
cmake --build "$out/cmake" >>"$out/cmake.log"
run_programs "$out/cmake"
if cmake -S "$out/src" -B "$out/cmake-refused" -DCMAKE_PREFIX_PATH="$prefix" \
    -DWANT_VERSION=99.0 >"$out/cmake-refused.log" 2>&1; then
    echo "find_package(shapecorr 99.0) accepted version $version"; exit 1
fi
grep -q "shapecorrConfig.cmake, version: $version" "$out/cmake-refused.log" ||
    { cat "$out/cmake-refused.log"; exit 1; }
# The staged tree, moved nowhere and with its library in lib/<multiarch>: the package is
# found relative to itself, not through the prefix it was configured for.
cmake -S "$out/src" -B "$out/cmake-staged" -DCMAKE_PREFIX_PATH="$stage" \
    -DWANT_VERSION="${version%.*}" >"$out/cmake-staged.log"
grep -q "shapecorr library: $stage/lib/$(gcc -print-multiarch)/libshapecorr.so$" \
    "$out/cmake-staged.log" || { echo "CMake did not find the staged library"; exit 1; }
grep -q "shapecorr library: $prefix/lib/libshapecorr.so$" "$out/cmake.log" ||
    { echo "CMake did not find the installed library"; exit 1; }
echo "install tests passed"
