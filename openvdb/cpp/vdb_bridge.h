// The C++ half of src/bridge.rs: OpenVDB grids in memory (read from a .vdb file, or built from
// voxelkit's arrays and written by OpenVDB's own writer), and OpenVDB's own tools.
#pragma once
#include "rust/cxx.h"
#include "trycatch.h"
#include <memory>
#include <openvdb/openvdb.h>

namespace voxelkit {

struct MetaEntry;
struct GridInfo;
struct GridArrays;
struct MeshCounts;

class GridSet {
public:
    explicit GridSet(openvdb::GridPtrVecPtr grids) : grids_(std::move(grids)) {}
    GridSet(const GridSet&) = delete;
    GridSet& operator=(const GridSet&) = delete;
    ~GridSet();
    size_t grid_count() const;
    GridInfo grid_info(size_t index) const;
    void read_leaves(size_t index, rust::Vec<int32_t>& leaf_origins, rust::Vec<uint64_t>& masks,
                     rust::Vec<float>& values, rust::Vec<int32_t>& tiles) const;
    void add_grid(const GridArrays& arrays);
    double level_set_volume(rust::Str name) const;
    MeshCounts volume_to_mesh(rust::Str name, double iso, double adaptivity, size_t threads) const;
    void write(rust::Str path, uint32_t compression, bool half);

private:
    openvdb::GridBase::ConstPtr grid(size_t index) const;
    openvdb::FloatGrid::ConstPtr float_grid(rust::Str name) const;
    openvdb::GridPtrVecPtr grids_;
};

std::unique_ptr<GridSet> open_vdb(rust::Str path);
std::unique_ptr<GridSet> new_grid_set();
double openvdb_level_set_volume(rust::Str path, rust::Str name);
uint64_t openvdb_reference(rust::Str kind, rust::Slice<const float> points, rust::Slice<const uint32_t> triangles,
                           double voxel_size, float band, size_t threads);

}  // namespace voxelkit

