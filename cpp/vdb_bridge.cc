// OpenVDB side of the bridge: builds LeafNodes from bulk leaf arrays in parallel, writes and
// reads .vdb files, and runs OpenVDB's own mesh conversions for benchmarks. Every exception becomes a
// Rust Err through cxx (see the trycatch override in vdb_bridge.h).
#include "voxelkit/cpp/vdb_bridge.h"
#include "voxelkit/src/ffi/vdb.rs.h"

#include <openvdb/tools/LevelSetMeasure.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <algorithm>
#include <limits>
#include <cerrno>
#include <cstring>
#include <exception>
#include <fstream>
#include <mutex>
#include <stdexcept>

namespace voxelkit {

namespace {

std::once_flag init_flag;

void ensure_initialized() { std::call_once(init_flag, [] { openvdb::initialize(); }); }

openvdb::math::Transform::Ptr make_transform(double voxel_size, const std::array<double, 3>& origin) {
    auto xform = openvdb::math::Transform::createLinearTransform(voxel_size);
    xform->postTranslate(openvdb::Vec3d(origin[0], origin[1], origin[2]));
    return xform;
}

// The grid types voxelkit reads (src/io/vdb_tree_structure.rs checks the same) and writes.
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

// Frees a grid's nodes without allocating when its scope is left by an exception (declare
// it after the grid's pointer, so that it runs first); a grid owned elsewhere too is left.
template <typename PtrT>
class FreeOnThrow {
public:
    explicit FreeOnThrow(const PtrT& grid) : grid_(grid), exceptions_(std::uncaught_exceptions()) {}
    FreeOnThrow(const FreeOnThrow&) = delete;
    FreeOnThrow& operator=(const FreeOnThrow&) = delete;
    ~FreeOnThrow() {
        if (std::uncaught_exceptions() > exceptions_ && grid_ && grid_.use_count() == 1) free_nodes(*grid_);
    }

private:
    const PtrT& grid_;
    int exceptions_;
};

// Builds one LeafNode per input leaf in parallel, then inserts them serially.
template <typename GridT, typename SetFn>
typename GridT::Ptr build_grid(rust::Slice<const int32_t> origins, rust::Slice<const uint64_t> masks,
                               typename GridT::ValueType background, SetFn set_value) {
    using LeafT = typename GridT::TreeType::LeafNodeType;
    const size_t count = origins.size() / 3;
    if (origins.size() != 3 * count || masks.size() != 8 * count)
        throw std::invalid_argument("leaf arrays of inconsistent length");
    std::vector<LeafT*> leaves(count, nullptr);
    size_t inserted = 0;
    typename GridT::Ptr grid;
    FreeOnThrow free_on_throw(grid);
    try {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, count), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i != r.end(); ++i) {
                openvdb::Coord c(origins[3 * i], origins[3 * i + 1], origins[3 * i + 2]);
                auto* leaf = new LeafT(c, background);
                for (openvdb::Index w = 0; w < 8; ++w) {
                    uint64_t bits = masks[8 * i + w];
                    while (bits) {
                        const openvdb::Index n = w * 64 + openvdb::Index(__builtin_ctzll(bits));
                        set_value(*leaf, i, n);
                        bits &= bits - 1;
                    }
                }
                leaves[i] = leaf;
            }
        });
        grid = GridT::create(background);
        typename GridT::Accessor acc = grid->getAccessor();
        for (; inserted < count; ++inserted) acc.addLeaf(leaves[inserted]);
    } catch (...) {
        // Out of memory part way: the leaves not in the tree yet (the guard frees the tree).
        for (size_t i = inserted; i < count; ++i) delete leaves[i];
        throw;
    }
    return grid;
}

}  // namespace

VdbWriter::~VdbWriter() { free_nodes(grids_); }

VdbFile::~VdbFile() {
    if (grids_) free_nodes(*grids_);
}

std::unique_ptr<VdbWriter> new_vdb_writer() {
    ensure_initialized();
    return std::make_unique<VdbWriter>();
}

void VdbWriter::add_level_set(rust::Str name, rust::Str density_name, double voxel_size,
                              std::array<double, 3> origin, rust::Slice<const int32_t> leaf_origins,
                              rust::Slice<const uint64_t> masks, rust::Slice<const float> values,
                              float background, bool is_signed, rust::Slice<const MetaEntry> metadata) {
    const size_t count = leaf_origins.size() / 3;
    if (values.size() != 512 * count) throw std::invalid_argument("level set: expected 512 values per leaf");
    // Voxels outside the band keep the background: +background outside, and, after the
    // signed flood fill, -background inside (tiles included), as OpenVDB's tools expect.
    auto grid = build_grid<openvdb::FloatGrid>(leaf_origins, masks, background,
                                               [&](auto& leaf, size_t i, openvdb::Index n) {
                                                   leaf.setValueOn(n, values[512 * i + n]);
                                               });
    FreeOnThrow free_on_throw(grid);
    if (is_signed) {
        for (auto leaf = grid->tree().beginLeaf(); leaf; ++leaf) {
            for (auto off = leaf->beginValueOff(); off; ++off) off.setValue(background);
        }
        openvdb::tools::signedFloodFill(grid->tree());
        grid->setGridClass(openvdb::GRID_LEVEL_SET);
    }
    auto xform = make_transform(voxel_size, origin);
    auto describe = [&](openvdb::GridBase& g, const std::string& n) {
        g.setName(n);
        g.setTransform(xform);
        for (const auto& m : metadata) g.insertMeta(std::string(m.key), openvdb::StringMetadata(std::string(m.value)));
    };
    if (is_signed && !density_name.empty()) {
        // Blender's volume object shows `density`: the fog volume of the same solid.
        auto fog = grid->deepCopy();
        FreeOnThrow free_fog_on_throw(fog);
        openvdb::tools::sdfToFogVolume(*fog, background);
        describe(*fog, std::string(density_name));
        grids_.push_back(fog);
    }
    describe(*grid, std::string(name));
    grids_.push_back(grid);
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

namespace {

// io::File writes through a stream whose errors it never checks, so a full disk gives a
// truncated file; this archive writes the same seekable format to a stream we check.
class CheckedArchive : public openvdb::io::Archive {
public:
    explicit CheckedArchive(uint32_t compression) { setCompression(compression); }
    void write_to(const std::string& path, const openvdb::GridPtrVec& grids) const {
        std::ofstream out(path, std::ios_base::out | std::ios_base::binary | std::ios_base::trunc);
        if (!out) throw std::runtime_error("cannot open for writing: " + std::string(std::strerror(errno)));
        Archive::write(out, grids, /*seekable=*/true);
        out.flush();
        if (!out) throw std::runtime_error("writing failed: " + std::string(std::strerror(errno)));
        out.close();
        if (out.fail()) throw std::runtime_error("closing failed: " + std::string(std::strerror(errno)));
    }
};

}  // namespace

void VdbWriter::write(rust::Str path, rust::Str compression, bool half, rust::Slice<const rust::String> only) const {
    const std::string c(compression);
    uint32_t flags = openvdb::io::COMPRESS_ACTIVE_MASK;
    if (c == "blosc") flags |= openvdb::io::COMPRESS_BLOSC;
    else if (c == "zip") flags |= openvdb::io::COMPRESS_ZIP;
    else if (c != "none") throw std::invalid_argument("unknown compression " + c + " (blosc, zip or none)");
    openvdb::GridPtrVec chosen;
    for (const auto& name : only) {
        const std::string n(name);
        auto found = std::find_if(grids_.begin(), grids_.end(), [&](const auto& g) { return g->getName() == n; });
        if (found == grids_.end()) {
            std::string names;
            for (const auto& g : grids_) names += (names.empty() ? "" : ", ") + g->getName();
            throw std::invalid_argument("no grid `" + n + "` to write; this output has " + names);
        }
    }
    for (const auto& g : grids_) {
        const bool wanted = only.empty() || std::any_of(only.begin(), only.end(), [&](const rust::String& n) {
                                                return std::string(n) == g->getName();
                                            });
        if (!wanted) continue;
        // Half precision applies to float and vector grids; bool grids have no floats.
        g->setSaveFloatAsHalf(half);
        chosen.push_back(g);
    }
    CheckedArchive(flags).write_to(std::string(path), chosen);
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
