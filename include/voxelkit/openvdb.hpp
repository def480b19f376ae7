// voxelkit and OpenVDB in one process, both ways: header-only C++17 over voxelkit.h,
// installed beside it. Link OpenVDB yourself (`$(pkg-config --cflags --libs tbb Imath)
// -lopenvdb`) and call openvdb::initialize() first.
//
//   openvdb::GridPtrVec grids = vk::to_openvdb(grid);        // what voxelkit's .vdb would hold
//   vk_grid* operand = vk::from_openvdb(*sphere);             // free with vk_grid_free
//
// Failures throw vk::error with voxelkit's message.
#pragma once

#include <voxelkit.h>

#include <openvdb/openvdb.h>
#include <openvdb/tools/SignedFloodFill.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace vk {

// A failed voxelkit call: what was called and voxelkit's message.
struct error : std::runtime_error {
    using std::runtime_error::runtime_error;
};

inline void check(vk_status status, const char* what) {
    if (status != VK_OK) throw error(std::string(what) + ": " + vk_last_error());
}

namespace detail {

// world = origin + voxel_size * index, as voxelkit places every grid.
inline openvdb::math::Transform::Ptr transform_of(const vk_grid* grid) {
    double voxel_size = 0.0, origin[3] = {0.0, 0.0, 0.0};
    check(vk_grid_transform(grid, &voxel_size, origin), "vk_grid_transform");
    auto xform = openvdb::math::Transform::createLinearTransform(voxel_size);
    xform->postTranslate(openvdb::Vec3d(origin[0], origin[1], origin[2]));
    return xform;
}

// The leaves of a voxelkit grid: origins (3 per leaf) and OpenVDB's mask words (8 per leaf).
struct Leaves {
    size_t count = 0;
    std::vector<int32_t> origins;
    std::vector<uint64_t> masks;
    explicit Leaves(const vk_grid* grid) {
        check(vk_grid_leaf_count(grid, &count), "vk_grid_leaf_count");
        origins.resize(3 * count);
        masks.resize(8 * count);
        check(vk_grid_copy_leaves(grid, 0, count, origins.data(), masks.data()), "vk_grid_copy_leaves");
    }
    openvdb::Coord origin(size_t i) const {
        return openvdb::Coord(origins[3 * i], origins[3 * i + 1], origins[3 * i + 2]);
    }
    bool on(size_t i, openvdb::Index n) const { return masks[8 * i + n / 64] >> (n % 64) & 1; }
};

// A grid of `leaves` whose voxel n of leaf i takes value(i, n), active where the mask says.
template <typename GridT, typename Value>
typename GridT::Ptr from_leaves(const Leaves& leaves, typename GridT::ValueType background,
                                Value value) {
    using LeafT = typename GridT::TreeType::LeafNodeType;
    auto out = GridT::create(background);
    auto accessor = out->getAccessor();
    for (size_t i = 0; i < leaves.count; ++i) {
        auto* leaf = new LeafT(leaves.origin(i), background);
        for (openvdb::Index n = 0; n < LeafT::SIZE; ++n) {
            if (leaves.on(i, n)) {
                leaf->setValueOn(n, value(i, n));
            } else {
                leaf->setValueOff(n, value(i, n));
            }
        }
        accessor.addLeaf(leaf);
    }
    return out;
}

// A vec3 channel (`normal` or `Cd`) of every leaf, when the grid has one: normals transform
// covariantly, colours are plain triples.
inline openvdb::GridBase::Ptr vector_grid(const vk_grid* grid, const Leaves& leaves,
                                          vk_status (*copy)(const vk_grid*, size_t, size_t, float*),
                                          const char* name, openvdb::VecType vector_type) {
    std::vector<float> values(3 * 512 * leaves.count);
    if (leaves.count == 0 || copy(grid, 0, leaves.count, values.data()) != VK_OK) return nullptr;
    auto out = from_leaves<openvdb::Vec3SGrid>(leaves, openvdb::Vec3s(0.0f), [&](size_t i, openvdb::Index n) {
        const float* v = &values[3 * (512 * i + n)];
        return openvdb::Vec3s(v[0], v[1], v[2]);
    });
    out->setName(name);
    out->setVectorType(vector_type);
    return out;
}

// Whole blocks of a voxelkit grid as OpenVDB tiles of level 1 (8^3) and 2 (128^3).
template <typename TreeT>
void add_tiles(const vk_grid* grid, TreeT& tree, typename TreeT::ValueType value) {
    size_t tiles = 0;
    check(vk_grid_tile_count(grid, &tiles), "vk_grid_tile_count");
    std::vector<int32_t> origins(3 * tiles), edges(tiles);
    check(vk_grid_copy_tiles(grid, 0, tiles, origins.data(), edges.data()), "vk_grid_copy_tiles");
    for (size_t i = 0; i < tiles; ++i) {
        const openvdb::Coord at(origins[3 * i], origins[3 * i + 1], origins[3 * i + 2]);
        tree.addTile(edges[i] == 8 ? 1 : 2, at, value, true);
    }
}

// What voxelkit takes from an OpenVDB tree: the leaves and whole blocks where `inside` holds
// (every voxel and tile of the tree, active or not, is asked).
template <typename TreeT, typename Inside>
vk_grid* voxels_of(const TreeT& tree, const openvdb::math::Transform& xform, Inside inside) {
    std::vector<int32_t> origins, tile_origins, edges;
    std::vector<uint64_t> masks;
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
        uint64_t words[8] = {0, 0, 0, 0, 0, 0, 0, 0};
        bool any = false;
        for (openvdb::Index n = 0; n < 512; ++n) {
            if (inside(leaf->getValue(n), leaf->isValueOn(n))) {
                words[n / 64] |= uint64_t(1) << (n % 64);
                any = true;
            }
        }
        if (!any) continue;
        const openvdb::Coord o = leaf->origin();
        origins.insert(origins.end(), {o.x(), o.y(), o.z()});
        masks.insert(masks.end(), words, words + 8);
    }
    for (auto it = tree.cbeginValueAll(); it; ++it) {
        if (!it.isTileValue() || !inside(*it, it.isValueOn())) continue;
        const openvdb::CoordBBox box = it.getBoundingBox();
        // Tiles of the root (4096^3) are given as the 128^3 blocks they hold.
        const int edge = it.getLevel() == 1 ? 8 : 128;
        for (int x = box.min().x(); x <= box.max().x(); x += edge)
            for (int y = box.min().y(); y <= box.max().y(); y += edge)
                for (int z = box.min().z(); z <= box.max().z(); z += edge) {
                    tile_origins.insert(tile_origins.end(), {x, y, z});
                    edges.push_back(edge);
                }
    }
    if (!xform.isLinear() || !xform.hasUniformScale())
        throw error("vk::from_openvdb: the grid's transform is not a uniform scale and a translation");
    const openvdb::Vec3d origin = xform.indexToWorld(openvdb::Vec3d(0.0));
    const double world_origin[3] = {origin.x(), origin.y(), origin.z()};
    vk_grid* out = nullptr;
    check(vk_grid_from_leaves(xform.voxelSize()[0], world_origin, masks.size() / 8, origins.data(),
                              masks.data(), edges.size(), tile_origins.data(), edges.data(), &out),
          "vk_grid_from_leaves");
    return out;
}

// The metadata voxelkit's file gives every grid: text, int64 and double items.
inline void add_metadata(const vk_grid* grid, openvdb::GridBase& out) {
    size_t count = 0;
    check(vk_grid_metadata_count(grid, &count), "vk_grid_metadata_count");
    for (size_t i = 0; i < count; ++i) {
        const char *key = nullptr, *text = nullptr;
        vk_meta_type type = VK_META_TEXT;
        int64_t integer = 0;
        double real = 0.0;
        check(vk_grid_metadata_item(grid, i, &key, &type, &text, &integer, &real), "vk_grid_metadata_item");
        if (type == VK_META_INT) {
            out.insertMeta(key, openvdb::Int64Metadata(integer));
        } else if (type == VK_META_REAL) {
            out.insertMeta(key, openvdb::DoubleMetadata(real));
        } else {
            out.insertMeta(key, openvdb::StringMetadata(text));
        }
    }
}

}  // namespace detail

// A voxelkit grid as the grids voxelkit's .vdb file of it holds, on its transform, with its
// metadata: a voxel
// set as the FOG_VOLUME `density` (1 on every voxel, whole blocks as tiles), a level set as
// the LEVEL_SET `surface` (signed distances in world units, its inside -background beyond
// the band), unsigned distances as `distance`; then `normal` and `Cd` where the grid has them.
inline openvdb::GridPtrVec to_openvdb(const vk_grid* grid) {
    vk_grid_class grid_class = VK_GRID_VOXELS;
    float background = 0.0f;
    check(vk_grid_get_class(grid, &grid_class, &background), "vk_grid_get_class");
    const detail::Leaves leaves(grid);
    openvdb::GridPtrVec out;
    if (grid_class == VK_GRID_VOXELS) {
        auto density = detail::from_leaves<openvdb::FloatGrid>(leaves, 0.0f, [](size_t, openvdb::Index) { return 1.0f; });
        // Whole blocks without a voxel off: density 0 where they are off is never asked.
        detail::add_tiles(grid, density->tree(), 1.0f);
        density->setGridClass(openvdb::GRID_FOG_VOLUME);
        density->setName("density");
        out.push_back(density);
    } else {
        std::vector<float> values(512 * leaves.count);
        if (leaves.count > 0)
            check(vk_grid_copy_values(grid, 0, leaves.count, values.data()), "vk_grid_copy_values");
        auto distances = detail::from_leaves<openvdb::FloatGrid>(
            leaves, background, [&](size_t i, openvdb::Index n) { return values[512 * i + n]; });
        if (grid_class == VK_GRID_LEVEL_SET) {
            openvdb::tools::signedFloodFill(distances->tree());
            distances->setGridClass(openvdb::GRID_LEVEL_SET);
            distances->setName("surface");
        } else {
            distances->setName("distance");
        }
        out.push_back(distances);
    }
    if (auto normal = detail::vector_grid(grid, leaves, vk_grid_copy_normals, "normal", openvdb::VEC_COVARIANT_NORMALIZE))
        out.push_back(normal);
    if (auto color = detail::vector_grid(grid, leaves, vk_grid_copy_colors, "Cd", openvdb::VEC_INVARIANT))
        out.push_back(color);
    for (auto& g : out) {
        g->setTransform(detail::transform_of(grid));
        detail::add_metadata(grid, *g);
    }
    return out;
}

// An OpenVDB grid as a voxelkit grid (free it with vk_grid_free): a level set as its inside
// (its negative voxels and tiles, active or not), a bool or mask grid's active voxels, any
// other grid's active voxels. The transform must be a uniform scale and a translation.
inline vk_grid* from_openvdb(const openvdb::GridBase& grid) {
    const auto& xform = grid.transform();
    if (const auto* f = dynamic_cast<const openvdb::FloatGrid*>(&grid)) {
        if (f->getGridClass() == openvdb::GRID_LEVEL_SET)
            return detail::voxels_of(f->tree(), xform, [](float v, bool) { return v < 0.0f; });
        return detail::voxels_of(f->tree(), xform, [](float, bool on) { return on; });
    }
    if (const auto* b = dynamic_cast<const openvdb::BoolGrid*>(&grid))
        return detail::voxels_of(b->tree(), xform, [](bool, bool on) { return on; });
    if (const auto* m = dynamic_cast<const openvdb::MaskGrid*>(&grid))
        return detail::voxels_of(m->tree(), xform, [](bool, bool on) { return on; });
    if (const auto* d = dynamic_cast<const openvdb::DoubleGrid*>(&grid))
        return detail::voxels_of(d->tree(), xform, [](double, bool on) { return on; });
    if (const auto* v = dynamic_cast<const openvdb::Vec3SGrid*>(&grid))
        return detail::voxels_of(v->tree(), xform, [](const openvdb::Vec3s&, bool on) { return on; });
    throw error("vk::from_openvdb: grid `" + grid.getName() + "` is of a type voxelkit does not take (" +
                grid.type() + ")");
}

}  // namespace vk
