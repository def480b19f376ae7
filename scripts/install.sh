#!/usr/bin/env bash
# Installs the C interface of voxelkit into PREFIX (default /usr/local): the static and shared
# libraries, include/voxelkit.h, pkg-config files (voxelkit, voxelkit-static) and a CMake
# package (find_package(voxelkit): targets voxelkit::voxelkit and voxelkit::voxelkit_static).
set -euo pipefail
cd "$(dirname "$0")/.."
prefix="${1:-/usr/local}"
cargo build --release --lib --quiet
version="$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)"
target="${CARGO_TARGET_DIR:-target}/release"
mkdir -p "$prefix/lib/pkgconfig" "$prefix/lib/cmake/voxelkit" "$prefix/include"
install -m 644 include/voxelkit.h "$prefix/include/"
install -m 644 "$target/libvoxelkit.a" "$prefix/lib/"
install -m 755 "$target/libvoxelkit.so" "$prefix/lib/"
# What the static library needs besides itself (rustc --print native-static-libs).
private="-lblosc -lz -losdCPU -lstdc++ -lgcc_s -lutil -lrt -lpthread -lm -ldl"
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
