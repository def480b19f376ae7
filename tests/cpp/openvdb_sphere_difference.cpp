// An OpenVDB-made sphere level set, taken into voxelkit by vk::from_openvdb, cut out of a
// voxelkit box: no voxel whose centre lies inside the sphere may remain. Prints the counts.
#include <voxelkit/openvdb.hpp>

#include <openvdb/tools/LevelSetSphere.h>

#include <cmath>
#include <cstdio>
#include <vector>

int main() {
    openvdb::initialize();
    const float radius = 0.6f, voxel = 0.02f;
    const openvdb::Vec3f centre(0.5f, 0.5f, 0.5f);
    auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(radius, centre, voxel);
    vk_grid* inside = vk::from_openvdb(*sphere);
    static const double p[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
    static const uint32_t t[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
    vk_mesh* cube = nullptr;
    vk_options* options = nullptr;
    vk_grid *box = nullptr, *carved = nullptr;
    vk::check(vk_mesh_from_triangles(p, 8, t, 12, &cube), "vk_mesh_from_triangles");
    vk::check(vk_options_new(&options), "vk_options_new");
    vk::check(vk_options_set_resolution(options, 50), "vk_options_set_resolution");
    vk::check(vk_fill_mesh(cube, options, &box, nullptr), "vk_fill_mesh");
    vk::check(vk_grid_combine(box, inside, VK_DIFFERENCE, 1, &carved), "vk_grid_combine");
    uint64_t sphere_voxels = 0, box_voxels = 0;
    size_t n = 0;
    vk::check(vk_grid_voxel_count(inside, &sphere_voxels), "vk_grid_voxel_count");
    vk::check(vk_grid_voxel_count(box, &box_voxels), "vk_grid_voxel_count");
    vk_grid_copy_voxels(carved, nullptr, 0, &n);
    std::vector<int64_t> ijk(3 * n);
    vk::check(vk_grid_copy_voxels(carved, ijk.data(), n, &n), "vk_grid_copy_voxels");
    double h = 0, origin[3];
    vk::check(vk_grid_transform(carved, &h, origin), "vk_grid_transform");
    size_t left_inside = 0;
    for (size_t k = 0; k < n; ++k) {
        double d2 = 0;
        for (int a = 0; a < 3; ++a) d2 += std::pow(origin[a] + h * double(ijk[3 * k + a]) - centre[a], 2);
        left_inside += std::sqrt(d2) < radius - h;
    }
    std::printf("sphere_voxels %llu\nsphere_expected %.1f\nbox_voxels %llu\ncarved_voxels %zu\nleft_inside %zu\n",
                (unsigned long long)sphere_voxels, 4.0 / 3.0 * M_PI * std::pow(radius / voxel, 3),
                (unsigned long long)box_voxels, n, left_inside);
    vk_grid_free(carved);
    vk_grid_free(box);
    vk_grid_free(inside);
    vk_options_free(options);
    vk_mesh_free(cube);
}
