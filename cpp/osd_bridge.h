// The C++ half of src/ffi/osd.rs: OpenSubdiv's own limit points, for checking voxelkit's
// Catmull-Clark evaluator live.
#pragma once
#include "rust/cxx.h"
#include "voxelkit/cpp/trycatch.h"
#include <cstdint>

namespace voxelkit {
namespace osd {

struct LimitPoints;

// Uniform refinement to `level`, then Far::PrimvarRefinerReal<double>::Limit at every vertex
// of every level-`level` face, reported once per face corner with its base face and (u, v);
// interior valence-2 and boundary vertices with 3 or more faces are left out (see the .cc).
LimitPoints limit_at_dyadic(rust::Slice<const double> positions, rust::Slice<const int32_t> face_sizes,
                            rust::Slice<const int32_t> face_verts, int32_t level);

// Bfr::Surface<double> (approximation level `approx_level`) at each (face, u, v).
LimitPoints limit_at(rust::Slice<const double> positions, rust::Slice<const int32_t> face_sizes,
                     rust::Slice<const int32_t> face_verts, rust::Slice<const uint32_t> faces,
                     rust::Slice<const double> uv, int32_t approx_level);

}  // namespace osd
}  // namespace voxelkit
