// Voxelizes a mesh through voxelkit's C interface, hands the grid to OpenVDB in the same
// process (vk::to_openvdb: no file in between), runs OpenVDB's volumeToMesh on it and writes
// the grid to a .vdb file.
//
//   voxelize_to_openvdb IN.obj RESOLUTION OUT.vdb
//
// Prints `voxelkit_voxels N`, `openvdb_voxels N`, `mesh_points N` and `mesh_quads N`.
#include <voxelkit/openvdb.hpp>

#include <openvdb/tools/VolumeToMesh.h>

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <vector>

namespace {

// Owns a voxelkit handle and frees it with its vk_*_free.
template <typename T, vk_status (*Free)(T*)>
struct Handle {
    T* ptr = nullptr;
    Handle() = default;
    Handle(const Handle&) = delete;
    Handle& operator=(const Handle&) = delete;
    ~Handle() { Free(ptr); }
};
using Mesh = Handle<vk_mesh, vk_mesh_free>;
using Options = Handle<vk_options, vk_options_free>;
using Grid = Handle<vk_grid, vk_grid_free>;

int print_progress(uint64_t done, uint64_t total, void* /*user_data*/) {
    if (total > 0) std::fprintf(stderr, "\rvoxelizing %3d%%", int(100 * done / total));
    return 0;
}

int run(const char* input, uint32_t resolution, const char* output) {
    Mesh mesh;
    vk::check(vk_mesh_load(input, &mesh.ptr), "vk_mesh_load");
    Options options;
    vk::check(vk_options_new(&options.ptr), "vk_options_new");
    vk::check(vk_options_set_resolution(options.ptr, resolution), "vk_options_set_resolution");
    vk::check(vk_options_set_separability(options.ptr, 26), "vk_options_set_separability");
    vk::check(vk_options_set_progress(options.ptr, print_progress, nullptr), "vk_options_set_progress");
    Grid grid;
    vk::check(vk_voxelize_mesh(mesh.ptr, options.ptr, &grid.ptr), "vk_voxelize_mesh");
    std::fprintf(stderr, "\n");
    uint64_t voxels = 0;
    vk::check(vk_grid_voxel_count(grid.ptr, &voxels), "vk_grid_voxel_count");

    openvdb::initialize();
    openvdb::GridPtrVec grids = vk::to_openvdb(grid.ptr);  // `density`, a fog volume
    auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(grids.front());
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(*density, points, quads, 0.5);

    openvdb::io::File file(output);
    file.write(grids);
    file.close();

    std::printf("voxelkit_voxels %" PRIu64 "\n", voxels);
    std::printf("openvdb_voxels %" PRIu64 "\n", uint64_t(density->activeVoxelCount()));
    std::printf("mesh_points %zu\nmesh_quads %zu\n", points.size(), quads.size());
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: %s IN.obj RESOLUTION OUT.vdb\n", argv[0]);
        return 2;
    }
    try {
        return run(argv[1], uint32_t(std::strtoul(argv[2], nullptr, 10)), argv[3]);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
}
