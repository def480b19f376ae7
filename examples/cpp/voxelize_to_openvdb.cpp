// Voxelizes a mesh through voxelkit's C interface, builds an openvdb::FloatGrid from the
// result leaf by leaf in the same process (no file in between), runs OpenVDB's volumeToMesh
// on it and writes the grid to a .vdb file.
//
//   voxelize_to_openvdb IN.obj RESOLUTION OUT.vdb
//
// Prints `voxelkit_voxels N`, `openvdb_voxels N`, `mesh_points N` and `mesh_quads N`.
#include <voxelkit.h>

#include <openvdb/openvdb.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

// Throws with voxelkit's message when a call fails.
void check(vk_status status, const char* what) {
    if (status != VK_OK)
        throw std::runtime_error(std::string(what) + ": " + vk_last_error());
}

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

// A fog volume with 1 on every voxel of `grid`, built leaf by leaf from the leaf masks, plus
// its tiles.
openvdb::FloatGrid::Ptr to_openvdb(const vk_grid* grid) {
    size_t leaves = 0;
    check(vk_grid_leaf_count(grid, &leaves), "vk_grid_leaf_count");
    std::vector<int32_t> origins(3 * leaves);
    std::vector<uint64_t> masks(8 * leaves);
    check(vk_grid_copy_leaves(grid, 0, leaves, origins.data(), masks.data()), "vk_grid_copy_leaves");
    double voxel_size = 0.0, origin[3] = {0.0, 0.0, 0.0};
    check(vk_grid_transform(grid, &voxel_size, origin), "vk_grid_transform");

    auto out = openvdb::FloatGrid::create(0.0f);
    auto xform = openvdb::math::Transform::createLinearTransform(voxel_size);
    xform->postTranslate(openvdb::Vec3d(origin[0], origin[1], origin[2]));
    out->setTransform(xform);
    out->setGridClass(openvdb::GRID_FOG_VOLUME);
    out->setName("density");
    auto accessor = out->getAccessor();
    using LeafT = openvdb::FloatGrid::TreeType::LeafNodeType;
    for (size_t i = 0; i < leaves; ++i) {
        // Same layout on both sides: voxel n = x*64 + y*8 + z, mask word x, bit y*8 + z.
        auto* leaf = new LeafT(openvdb::Coord(origins[3 * i], origins[3 * i + 1], origins[3 * i + 2]), 0.0f);
        for (openvdb::Index w = 0; w < 8; ++w) {
            for (uint64_t bits = masks[8 * i + w]; bits != 0; bits &= bits - 1) {
                leaf->setValueOn(w * 64 + openvdb::Index(__builtin_ctzll(bits)), 1.0f);
            }
        }
        accessor.addLeaf(leaf);
    }
    // Whole blocks (a solid's inside) come as tiles: OpenVDB's tiles of level 1 (8^3) and 2 (128^3).
    size_t tiles = 0;
    check(vk_grid_tile_count(grid, &tiles), "vk_grid_tile_count");
    std::vector<int32_t> tile_origins(3 * tiles), edges(tiles);
    check(vk_grid_copy_tiles(grid, 0, tiles, tile_origins.data(), edges.data()), "vk_grid_copy_tiles");
    for (size_t i = 0; i < tiles; ++i) {
        const openvdb::Coord at(tile_origins[3 * i], tile_origins[3 * i + 1], tile_origins[3 * i + 2]);
        out->tree().addTile(edges[i] == 8 ? 1 : 2, at, 1.0f, true);
    }
    return out;
}

int run(const char* input, uint32_t resolution, const char* output) {
    Mesh mesh;
    check(vk_mesh_load(input, &mesh.ptr), "vk_mesh_load");
    Options options;
    check(vk_options_new(&options.ptr), "vk_options_new");
    check(vk_options_set_resolution(options.ptr, resolution), "vk_options_set_resolution");
    check(vk_options_set_separability(options.ptr, 26), "vk_options_set_separability");
    check(vk_options_set_progress(options.ptr, print_progress, nullptr), "vk_options_set_progress");
    Grid grid;
    check(vk_voxelize_mesh(mesh.ptr, options.ptr, &grid.ptr), "vk_voxelize_mesh");
    std::fprintf(stderr, "\n");
    uint64_t voxels = 0;
    check(vk_grid_voxel_count(grid.ptr, &voxels), "vk_grid_voxel_count");

    openvdb::initialize();
    openvdb::FloatGrid::Ptr density = to_openvdb(grid.ptr);
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(*density, points, quads, 0.5);

    openvdb::io::File file(output);
    file.write({density});
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
