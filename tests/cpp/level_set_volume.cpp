// A mesh's level set made in memory, handed to OpenVDB by vk::to_openvdb, measured by
// levelSetVolume and meshed by volumeToMesh.   level_set_volume MESH RESOLUTION
#include <voxelkit/openvdb.hpp>

#include <openvdb/tools/LevelSetMeasure.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
    if (argc != 3) return 2;
    openvdb::initialize();
    vk_mesh* mesh = nullptr;
    vk_options* options = nullptr;
    vk_grid* grid = nullptr;
    vk::check(vk_mesh_load(argv[1], &mesh), "vk_mesh_load");
    vk::check(vk_options_new(&options), "vk_options_new");
    vk::check(vk_options_set_resolution(options, uint32_t(std::atoi(argv[2]))), "vk_options_set_resolution");
    vk::check(vk_options_set_sdf(options, 3.0), "vk_options_set_sdf");
    vk::check(vk_voxelize_mesh(mesh, options, &grid), "vk_voxelize_mesh");
    auto surface = openvdb::gridPtrCast<openvdb::FloatGrid>(openvdb::findGridByName(vk::to_openvdb(grid), "surface"));
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(*surface, points, quads, 0.0);
    std::printf("volume %.9g\npoints %zu\nquads %zu\n", openvdb::tools::levelSetVolume(*surface), points.size(), quads.size());
    vk_grid_free(grid);
    vk_options_free(options);
    vk_mesh_free(mesh);
}
