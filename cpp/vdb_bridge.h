// The C++ half of src/ffi/vdb.rs: OpenVDB file I/O and OpenVDB's own mesh conversions for benchmarks.
#pragma once
#include "rust/cxx.h"
#include "voxelkit/cpp/trycatch.h"
#include <memory>
#include <openvdb/openvdb.h>

namespace voxelkit {

struct MetaEntry;
struct GridInfo;

class VdbWriter {
public:
    VdbWriter() = default;
    VdbWriter(const VdbWriter&) = delete;
    VdbWriter& operator=(const VdbWriter&) = delete;
    ~VdbWriter();
    void add_level_set(rust::Str name, rust::Str density_name, double voxel_size, std::array<double, 3> origin,
                       rust::Slice<const int32_t> leaf_origins, rust::Slice<const uint64_t> masks,
                       rust::Slice<const float> values, float background, bool is_signed,
                       rust::Slice<const MetaEntry> metadata);
    void write(rust::Str path, rust::Str compression, bool half, rust::Slice<const rust::String> only) const;

private:
    openvdb::GridPtrVec grids_;
};

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

std::unique_ptr<VdbWriter> new_vdb_writer();
std::unique_ptr<VdbFile> open_vdb(rust::Str path);
double openvdb_level_set_volume(rust::Str path, rust::Str name);
uint64_t openvdb_reference(rust::Str kind, rust::Slice<const float> points, rust::Slice<const uint32_t> triangles,
                           double voxel_size, float band, size_t threads);

}  // namespace voxelkit

