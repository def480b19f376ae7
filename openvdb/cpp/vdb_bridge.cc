// OpenVDB side of the bridge, for voxelkit's tests and benchmarks: reads .vdb files into bulk leaf
// arrays (an independent check of voxelkit's own reader and writer) and runs OpenVDB's own tools
// (levelSetVolume, mesh conversions). Every exception becomes a Rust Err through cxx (see the
// trycatch override in trycatch.h).
#include "voxelkit-openvdb/cpp/vdb_bridge.h"
#include "voxelkit-openvdb/src/bridge.rs.h"

#include <openvdb/tools/LevelSetMeasure.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/global_control.h>
#include <algorithm>
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

VdbFile::~VdbFile() {
    if (grids_) free_nodes(*grids_);
}

double openvdb_level_set_volume(rust::Str path, rust::Str name) {
    ensure_initialized();
    openvdb::io::File file{std::string(path)};
    file.open(/*delayLoad=*/false);
    auto base = file.readGrid(std::string(name));
    file.close();
    auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid) throw std::invalid_argument("grid " + std::string(name) + " is not a FloatGrid");
    return openvdb::tools::levelSetVolume(*grid);
}

std::unique_ptr<VdbFile> open_vdb(rust::Str path) {
    ensure_initialized();
    openvdb::io::File file{std::string(path)};
    file.open(/*delayLoad=*/false);  // read now: delayed loading trusts the file's per-leaf metadata
    auto grids = file.getGrids();
    file.close();
    return std::make_unique<VdbFile>(grids);
}

size_t VdbFile::grid_count() const { return grids_->size(); }

openvdb::GridBase::ConstPtr VdbFile::grid(size_t index) const {
    if (index >= grids_->size()) throw std::out_of_range("grid index out of range");
    return (*grids_)[index];
}

GridInfo VdbFile::grid_info(size_t index) const {
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

void VdbFile::read_leaves(size_t index, rust::Vec<int32_t>& leaf_origins, rust::Vec<uint64_t>& masks,
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
