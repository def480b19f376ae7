// The C++ half of src/bridge.rs: reading .vdb files and OpenVDB's own tools for tests and benchmarks.
#pragma once
#include "rust/cxx.h"
#include "trycatch.h"
#include <memory>
#include <openvdb/openvdb.h>

namespace voxelkit {

struct MetaEntry;
struct GridInfo;

class VdbFile {
public:
    explicit VdbFile(openvdb::GridPtrVecPtr grids) : grids_(std::move(grids)) {}
    VdbFile(const VdbFile&) = delete;
    VdbFile& operator=(const VdbFile&) = delete;
    ~VdbFile();
    size_t grid_count() const;
    GridInfo grid_info(size_t index) const;
    void read_leaves(size_t index, rust::Vec<int32_t>& leaf_origins, rust::Vec<uint64_t>& masks,
                     rust::Vec<float>& values, rust::Vec<int32_t>& tiles) const;

private:
    openvdb::GridBase::ConstPtr grid(size_t index) const;
    openvdb::GridPtrVecPtr grids_;
};

std::unique_ptr<VdbFile> open_vdb(rust::Str path);
double openvdb_level_set_volume(rust::Str path, rust::Str name);
uint64_t openvdb_reference(rust::Str kind, rust::Slice<const float> points, rust::Slice<const uint32_t> triangles,
                           double voxel_size, float band, size_t threads);

}  // namespace voxelkit

