// OpenVDB side of the bridge: reads .vdb files into bulk leaf arrays (an independent check of
// voxelkit's own reader and writer), builds OpenVDB grids from voxelkit's arrays and writes them
// with OpenVDB's own io::File, and runs OpenVDB's own tools (levelSetVolume, mesh conversions).
// Every exception becomes a Rust Err through cxx (see the trycatch override in trycatch.h).
#include "voxelkit-openvdb/cpp/vdb_bridge.h"
#include "voxelkit-openvdb/src/bridge.rs.h"

#include <voxelkit/openvdb.hpp>

#include <openvdb/tools/LevelSetMeasure.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/global_control.h>
#include <algorithm>
#include <chrono>
#include <limits>
#include <exception>
#include <mutex>
#include <stdexcept>

namespace voxelkit {

namespace {

std::once_flag init_flag;

void ensure_initialized() { std::call_once(init_flag, [] { openvdb::initialize(); }); }

// The grid types voxelkit reads (voxelkit's src/io/vdb_tree_structure.rs checks the same).
using KnownGridTypes =
    openvdb::NumericGridTypes::Append<openvdb::Vec3GridTypes>::Append<openvdb::BoolGrid, openvdb::MaskGrid>;

// OpenVDB's tree destructor first gathers every node into a vector: an allocation that can
// throw while memory is short, inside a noexcept destructor (std::terminate). Deleting from
// the root down allocates nothing, and the destructor then finds an empty tree.
void free_nodes(openvdb::GridBase& grid) noexcept {
    auto clear = [](auto& typed) { typed.tree().root().clear(); };
    grid.apply<KnownGridTypes>(clear);
}

void free_nodes(const openvdb::GridPtrVec& grids) noexcept {
    for (const auto& g : grids)
        if (g && g.use_count() == 1) free_nodes(*g);
}

}  // namespace

GridSet::~GridSet() {
    if (grids_) free_nodes(*grids_);
}

double openvdb_level_set_volume(rust::Str path, rust::Str name) { return open_vdb(path)->level_set_volume(name); }

openvdb::FloatGrid::ConstPtr GridSet::float_grid(rust::Str name) const {
    for (const auto& base : *grids_) {
        if (base->getName() != std::string(name)) continue;
        auto grid = openvdb::gridConstPtrCast<openvdb::FloatGrid>(base);
        if (!grid) throw std::invalid_argument("grid " + std::string(name) + " is not a FloatGrid");
        return grid;
    }
    throw std::invalid_argument("no grid named " + std::string(name));
}

double GridSet::level_set_volume(rust::Str name) const { return openvdb::tools::levelSetVolume(*float_grid(name)); }

MeshCounts GridSet::volume_to_mesh(rust::Str name, double iso, double adaptivity, size_t threads) const {
    auto grid = float_grid(name);
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<openvdb::Vec4I> quads;
    const auto start = std::chrono::steady_clock::now();
    openvdb::tools::volumeToMesh(*grid, points, triangles, quads, iso, adaptivity);
    const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
    return MeshCounts{took.count(), points.size(), triangles.size(), quads.size()};
}

std::unique_ptr<GridSet> open_vdb(rust::Str path) {
    ensure_initialized();
    openvdb::io::File file{std::string(path)};
    file.open(/*delayLoad=*/false);  // read now: delayed loading trusts the file's per-leaf metadata
    auto grids = file.getGrids();
    file.close();
    return std::make_unique<GridSet>(grids);
}

std::unique_ptr<GridSet> new_grid_set() {
    ensure_initialized();
    return std::make_unique<GridSet>(std::make_shared<openvdb::GridPtrVec>());
}

size_t GridSet::grid_count() const { return grids_->size(); }

openvdb::GridBase::ConstPtr GridSet::grid(size_t index) const {
    if (index >= grids_->size()) throw std::out_of_range("grid index out of range");
    return (*grids_)[index];
}

GridInfo GridSet::grid_info(size_t index) const {
    auto g = grid(index);
    GridInfo info;
    info.name = g->getName();
    info.value_type = g->valueType();
    info.grid_class = openvdb::GridBase::gridClassToString(g->getGridClass());
    const auto& xform = g->transform();
    const auto vs = xform.voxelSize();
    info.voxel_size = {vs[0], vs[1], vs[2]};
    const auto o = xform.indexToWorld(openvdb::Vec3d(0.0));
    info.origin = {o[0], o[1], o[2]};
    // A uniform scale plus translation, up to rounding in the stored matrix.
    const double h = vs[0];
    auto close = [h](const openvdb::Vec3d& a, const openvdb::Vec3d& b) { return (a - b).length() <= 1e-9 * h; };
    info.uniform_linear = xform.isLinear() && close(vs, openvdb::Vec3d(h)) &&
                          close(xform.indexToWorld(openvdb::Vec3d(1, 0, 0)) - o, openvdb::Vec3d(h, 0, 0)) &&
                          close(xform.indexToWorld(openvdb::Vec3d(0, 1, 0)) - o, openvdb::Vec3d(0, h, 0)) &&
                          close(xform.indexToWorld(openvdb::Vec3d(0, 0, 1)) - o, openvdb::Vec3d(0, 0, h));
    info.active_voxels = g->activeVoxelCount();
    info.leaf_count = 0;
    const auto bbox = g->evalActiveVoxelBoundingBox();
    info.bbox_min = {bbox.min().x(), bbox.min().y(), bbox.min().z()};
    info.bbox_max = {bbox.max().x(), bbox.max().y(), bbox.max().z()};
    for (auto it = g->beginMeta(); it != g->endMeta(); ++it) {
        if (it->first.rfind("file_", 0) == 0) continue;  // OpenVDB's own bookkeeping
        info.metadata.push_back(MetaEntry{rust::String(it->first), rust::String(it->second->str())});
    }
    info.tile_count = 0;
    auto count_leaves = [&](auto typed) {
        info.leaf_count = typed->tree().leafCount();
        for (auto it = typed->tree().cbeginValueOn(); it; ++it) {
            if (it.isVoxelValue()) continue;
            const auto dim = it.getBoundingBox().dim().x();
            info.tile_count += dim <= 128 ? 1 : uint64_t(dim / 128) * (dim / 128) * (dim / 128);
        }
    };
    if (auto b = openvdb::gridConstPtrCast<openvdb::BoolGrid>(g)) count_leaves(b);
    else if (auto m = openvdb::gridConstPtrCast<openvdb::MaskGrid>(g)) count_leaves(m);
    else if (auto f = openvdb::gridConstPtrCast<openvdb::FloatGrid>(g)) count_leaves(f);
    else if (auto v = openvdb::gridConstPtrCast<openvdb::Vec3SGrid>(g)) count_leaves(v);
    return info;
}

namespace {
template <typename GridT>
void copy_leaves(const GridT& src, rust::Vec<int32_t>& origins, rust::Vec<uint64_t>& masks,
                 rust::Vec<float>* values, rust::Vec<int32_t>& tiles) {
    const auto& tree = src.tree();
    for (auto it = tree.cbeginLeaf(); it; ++it) {
        const auto& mask = it->getValueMask();
        if (mask.isOff()) continue;
        const auto o = it->origin();
        origins.push_back(o.x());
        origins.push_back(o.y());
        origins.push_back(o.z());
        for (openvdb::Index w = 0; w < 8; ++w) masks.push_back(mask.template getWord<openvdb::Index64>(w));
        if (values) {
            for (openvdb::Index n = 0; n < 512; ++n) {
                const auto v = it->getValue(n);
                if constexpr (std::is_same_v<typename GridT::ValueType, openvdb::Vec3s>) {
                    values->push_back(v.x());
                    values->push_back(v.y());
                    values->push_back(v.z());
                } else {
                    values->push_back(float(v));
                }
            }
        }
    }
    auto push_tile = [&](const openvdb::Coord& o, int32_t edge) {
        tiles.push_back(o.x());
        tiles.push_back(o.y());
        tiles.push_back(o.z());
        tiles.push_back(edge);
    };
    for (auto it = tree.cbeginValueOn(); it; ++it) {
        if (it.isVoxelValue()) continue;
        const auto box = it.getBoundingBox();
        const int32_t edge = box.dim().x();
        if (edge <= 128) {
            push_tile(box.min(), edge);
            continue;
        }
        // A root tile (4096^3): its 128^3 blocks.
        for (int32_t x = 0; x < edge; x += 128)
            for (int32_t y = 0; y < edge; y += 128)
                for (int32_t z = 0; z < edge; z += 128) push_tile(box.min().offsetBy(x, y, z), 128);
    }
}
}  // namespace

void GridSet::read_leaves(size_t index, rust::Vec<int32_t>& leaf_origins, rust::Vec<uint64_t>& masks,
                          rust::Vec<float>& values, rust::Vec<int32_t>& tiles) const {
    auto g = grid(index);
    if (auto b = openvdb::gridConstPtrCast<openvdb::BoolGrid>(g)) copy_leaves(*b, leaf_origins, masks, nullptr, tiles);
    else if (auto m = openvdb::gridConstPtrCast<openvdb::MaskGrid>(g))
        copy_leaves(*m, leaf_origins, masks, nullptr, tiles);
    else if (auto f = openvdb::gridConstPtrCast<openvdb::FloatGrid>(g))
        copy_leaves(*f, leaf_origins, masks, &values, tiles);
    else if (auto v = openvdb::gridConstPtrCast<openvdb::Vec3SGrid>(g))
        copy_leaves(*v, leaf_origins, masks, &values, tiles);
    else throw std::invalid_argument("grid '" + g->getName() + "' has value type " + g->valueType() +
                                     "; only bool, mask, float and vec3s grids can be read");
}

namespace {
// The grid of the arrays, built as the C++ header voxelkit installs builds it.
template <typename GridT>
openvdb::GridBase::Ptr build_grid(const GridArrays& a, size_t components) {
    const size_t leaves = a.leaf_origins.size() / 3;
    if (a.masks.size() != 8 * leaves || a.values.size() != 512 * components * leaves || a.tiles.size() % 4 != 0)
        throw std::invalid_argument("grid " + std::string(a.name) + ": the arrays' lengths disagree");
    return vk::detail::grid_from_arrays<GridT>(a.background, leaves, a.leaf_origins.data(), a.masks.data(),
                                               a.values.data(), a.tiles.size() / 4, a.tiles.data(), a.tiles_active,
                                               a.tile_value);
}
}  // namespace

void GridSet::add_grid(const GridArrays& a) {
    const std::string type(a.value_type);
    openvdb::GridBase::Ptr grid;
    if (type == "float") grid = build_grid<openvdb::FloatGrid>(a, 1);
    else if (type == "vec3s") grid = build_grid<openvdb::Vec3SGrid>(a, 3);
    else if (type == "bool") grid = build_grid<openvdb::BoolGrid>(a, 0);
    else throw std::invalid_argument("grid " + std::string(a.name) + ": value type " + type + " is not bool, float or vec3s");
    grid->setName(std::string(a.name));
    auto xform = openvdb::math::Transform::createLinearTransform(a.voxel_size);
    xform->postTranslate(openvdb::Vec3d(a.origin[0], a.origin[1], a.origin[2]));
    grid->setTransform(xform);
    if (!a.grid_class.empty()) grid->setGridClass(openvdb::GridBase::stringToGridClass(std::string(a.grid_class)));
    if (!a.vector_type.empty()) grid->setVectorType(openvdb::GridBase::stringToVecType(std::string(a.vector_type)));
    for (const auto& m : a.metadata) {
        const std::string key(m.key);
        const std::string kind(m.kind);
        if (kind == "string") grid->insertMeta(key, openvdb::StringMetadata(std::string(m.text)));
        else if (kind == "int64") grid->insertMeta(key, openvdb::Int64Metadata(m.integer));
        else grid->insertMeta(key, openvdb::DoubleMetadata(m.real));
    }
    grids_->push_back(grid);
}

void GridSet::write(rust::Str path, uint32_t compression, bool half) {
    for (const auto& g : *grids_) g->setSaveFloatAsHalf(half);
    openvdb::io::File file{std::string(path)};
    file.setCompression(compression | openvdb::io::COMPRESS_ACTIVE_MASK);
    file.write(*grids_);
    file.close();
}

uint64_t openvdb_reference(rust::Str kind, rust::Slice<const float> points, rust::Slice<const uint32_t> triangles,
                           double voxel_size, float band, size_t threads) {
    ensure_initialized();
    const std::string k(kind);
    std::vector<openvdb::Vec3s> pts(points.size() / 3);
    for (size_t i = 0; i < pts.size(); ++i) pts[i] = openvdb::Vec3s(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
    std::vector<openvdb::Vec3I> tris(triangles.size() / 3);
    for (size_t i = 0; i < tris.size(); ++i)
        tris[i] = openvdb::Vec3I(triangles[3 * i], triangles[3 * i + 1], triangles[3 * i + 2]);
    const std::vector<openvdb::Vec4I> no_quads;
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    auto xform = openvdb::math::Transform::createLinearTransform(voxel_size);
    // meshToVolume reads index space; the other two take world points, as a user calls them.
    std::vector<openvdb::Vec3s> world(pts);
    for (auto& p : world) p *= float(voxel_size);
    if (k == "unsigned") {
        return openvdb::tools::meshToUnsignedDistanceField<openvdb::FloatGrid>(*xform, world, tris, no_quads, band)
            ->activeVoxelCount();
    }
    if (k == "level-set" || k == "solid") {
        auto sdf = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xform, world, tris, no_quads, band);
        if (k == "level-set") return sdf->activeVoxelCount();
        return openvdb::tools::sdfInteriorMask(*sdf)->activeVoxelCount();
    }
    if (k == "filled") {
        openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> mesh(pts, tris);
        return openvdb::tools::meshToVolume<openvdb::FloatGrid>(mesh, *xform, band, std::numeric_limits<float>::max())
            ->activeVoxelCount();
    }
    throw std::invalid_argument("unknown reference " + k);
}

}  // namespace voxelkit
