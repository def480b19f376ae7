#!/usr/bin/env bash
# Installs the C interface of voxelkit into PREFIX (default /usr/local): the static and shared
# libraries (stripped; the shared one's debug information in libvoxelkit.so.debug beside it),
# include/voxelkit.h and include/voxelkit/openvdb.hpp (the C++ bridge to OpenVDB), pkg-config
# files (voxelkit, voxelkit-static) and a CMake package (find_package(voxelkit): targets
# voxelkit::voxelkit and voxelkit::voxelkit_static).
set -euo pipefail
cd "$(dirname "$0")/.."
prefix="${1:-/usr/local}"
cargo build --release --lib --quiet
version="$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)"
target="${CARGO_TARGET_DIR:-target}/release"
mkdir -p "$prefix/lib/pkgconfig" "$prefix/lib/cmake/voxelkit" "$prefix/include"
mkdir -p "$prefix/include/voxelkit"
install -m 644 include/voxelkit.h "$prefix/include/"
install -m 644 include/voxelkit/openvdb.hpp "$prefix/include/voxelkit/"
# What the static library needs besides itself (rustc --print native-static-libs).
private="-lblosc -llz4 -lz -losdCPU -lstdc++ -lgcc_s -lutil -lrt -lpthread -lm -ldl"
install -m 644 "$target/libvoxelkit.a" "$prefix/lib/"
strip --strip-debug "$prefix/lib/libvoxelkit.a"
# The shared library is linked here from the static one, so that it exports the C interface
# and nothing else (src/capi.map) and drops what the interface never reaches; its debug
# information goes beside it (libvoxelkit.so.debug, found by gdb through its debug link).
gcc -shared -o "$prefix/lib/libvoxelkit.so" -Wl,-soname,libvoxelkit.so \
    -Wl,--version-script=src/capi.map -Wl,--gc-sections \
    -Wl,--whole-archive "$target/libvoxelkit.a" -Wl,--no-whole-archive $private
objcopy --only-keep-debug "$prefix/lib/libvoxelkit.so" "$prefix/lib/libvoxelkit.so.debug"
strip --strip-debug --strip-unneeded "$prefix/lib/libvoxelkit.so"
objcopy --add-gnu-debuglink="$prefix/lib/libvoxelkit.so.debug" "$prefix/lib/libvoxelkit.so"
for name in voxelkit voxelkit-static; do
    sed -e "s|@PREFIX@|$prefix|" -e "s|@VERSION@|$version|" -e "s|@PRIVATE@|$private|" \
        "cmake/$name.pc.in" > "$prefix/lib/pkgconfig/$name.pc"
done
cmake_libs="$(echo ${private//-l/} | tr ' ' ';')"
sed -e "s|@PRIVATE@|$cmake_libs|" cmake/voxelkitConfig.cmake.in \
    > "$prefix/lib/cmake/voxelkit/voxelkitConfig.cmake"
sed -e "s|@VERSION@|$version|" cmake/voxelkitConfigVersion.cmake.in \
    > "$prefix/lib/cmake/voxelkit/voxelkitConfigVersion.cmake"
echo "voxelkit $version installed in $prefix"
