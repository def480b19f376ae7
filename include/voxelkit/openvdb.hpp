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

#include <cstdint>
#include <stdexcept>
#include <string>
#include <type_traits>
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

// A grid of GridT from voxelkit's arrays, in the layout vk_grid_export_arrays gives: per leaf
// its origin (3 int32), mask words (8 uint64, OpenVDB's) and every value (512 floats, 3 x 512
// for Vec3s, none for bool: true where active); per tile its origin and edge (8 or 128), each
// holding `tile_value`, active or not. Also used by voxelkit's Rust bridge to OpenVDB.
template <typename GridT>
typename GridT::Ptr grid_from_arrays(float background, size_t leaf_count, const int32_t* origins,
                                     const uint64_t* masks, const float* values, size_t tile_count,
                                     const int32_t* tiles, bool tiles_active, float tile_value) {
    using ValueT = typename GridT::ValueType;
    constexpr bool vector = std::is_same_v<ValueT, openvdb::Vec3s>;
    constexpr bool boolean = std::is_same_v<ValueT, bool>;
    auto grid = GridT::create(ValueT(background));
    auto& tree = grid->tree();
    for (size_t i = 0; i < leaf_count; ++i) {
        auto* leaf = tree.touchLeaf(openvdb::Coord(origins[3 * i], origins[3 * i + 1], origins[3 * i + 2]));
        typename GridT::TreeType::LeafNodeType::NodeMaskType mask;
        for (openvdb::Index w = 0; w < 8; ++w) mask.template getWord<openvdb::Index64>(w) = masks[8 * i + w];
        for (openvdb::Index n = 0; n < 512; ++n) {
            if constexpr (boolean) {
                leaf->setValueOnly(n, mask.isOn(n));
            } else if constexpr (vector) {
                const float* v = values + 3 * (512 * i + n);
                leaf->setValueOnly(n, ValueT(v[0], v[1], v[2]));
            } else {
                leaf->setValueOnly(n, values[512 * i + n]);
            }
        }
        leaf->setValueMask(mask);
    }
    for (size_t i = 0; i < tile_count; ++i) {
        const int32_t* t = tiles + 4 * i;
        tree.addTile(t[3] == 8 ? 1 : 2, openvdb::Coord(t[0], t[1], t[2]), ValueT(tile_value), tiles_active);
    }
    return grid;
}

// Grid `index` of what voxelkit writes for `grid` (as `options` choose, NULL: the defaults).
template <typename GridT>
typename GridT::Ptr exported_grid(const vk_grid* grid, const vk_options* options, size_t index,
                                  const vk_export_info& info) {
    const size_t per_leaf = info.value_type == VK_VALUE_VEC3S ? 3 * 512 : info.value_type == VK_VALUE_FLOAT ? 512 : 0;
    std::vector<int32_t> origins(3 * info.leaf_count), tiles(4 * info.tile_count);
    std::vector<uint64_t> masks(8 * info.leaf_count);
    std::vector<float> values(per_leaf * info.leaf_count);
    check(vk_grid_export_arrays(grid, options, index, origins.data(), masks.data(), values.data(), tiles.data()),
          "vk_grid_export_arrays");
    return grid_from_arrays<GridT>(info.background, info.leaf_count, origins.data(), masks.data(), values.data(),
                                   info.tile_count, tiles.data(), info.tiles_active != 0, info.tile_value);
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

// A voxelkit grid as the grids voxelkit's .vdb file of it holds (those `options` choose; NULL:
// all but `voxels`), on its transform, with its metadata: a voxel set as the FOG_VOLUME
// `density` (1 on every voxel, whole blocks as tiles), `normal` and `Cd` where the grid has
// them and the bool grids beside it (a solid's `shell` and `interior` ...); a level set as
// its fog volume `density` and the LEVEL_SET `surface` (signed distances in world units, its
// inside -background beyond the band, inactive tiles there); unsigned distances as `distance`.
inline openvdb::GridPtrVec to_openvdb(const vk_grid* grid, const vk_options* options = nullptr) {
    size_t count = 0;
    check(vk_grid_export_count(grid, options, &count), "vk_grid_export_count");
    openvdb::GridPtrVec out;
    for (size_t i = 0; i < count; ++i) {
        vk_export_info info;
        check(vk_grid_export_info(grid, options, i, &info), "vk_grid_export_info");
        openvdb::GridBase::Ptr g;
        if (info.value_type == VK_VALUE_BOOL) g = detail::exported_grid<openvdb::BoolGrid>(grid, options, i, info);
        else if (info.value_type == VK_VALUE_VEC3S) g = detail::exported_grid<openvdb::Vec3SGrid>(grid, options, i, info);
        else g = detail::exported_grid<openvdb::FloatGrid>(grid, options, i, info);
        g->setName(info.name);
        if (info.grid_class == VK_CLASS_FOG_VOLUME) g->setGridClass(openvdb::GRID_FOG_VOLUME);
        if (info.grid_class == VK_CLASS_LEVEL_SET) g->setGridClass(openvdb::GRID_LEVEL_SET);
        if (info.vector_type == VK_VECTOR_COVARIANT_NORMALIZE) g->setVectorType(openvdb::VEC_COVARIANT_NORMALIZE);
        if (info.vector_type == VK_VECTOR_INVARIANT) g->setVectorType(openvdb::VEC_INVARIANT);
        g->setTransform(detail::transform_of(grid));
        detail::add_metadata(grid, *g);
        out.push_back(g);
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
