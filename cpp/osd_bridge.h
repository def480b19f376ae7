// The C++ half of src/ffi/osd.rs: OpenSubdiv's own limit points, for checking voxelkit's
// Catmull-Clark evaluator live.
#pragma once
#include "rust/cxx.h"
#include "voxelkit/cpp/trycatch.h"
#include <cstdint>

namespace voxelkit {
namespace osd {

struct LimitPoints;
struct ControlCage;

// Uniform refinement to `level`, then Far::PrimvarRefinerReal<double>::Limit at every vertex
// of every level-`level` face whose (u, v) lies on the 2^-lattice_level lattice, reported once
// per face corner with its base face and (u, v); interior valence-2 vertices, boundary vertices
// with 3 or more faces and vertices on tagged creases are left out (see the .cc).
LimitPoints limit_at_dyadic(ControlCage const& cage, int32_t level, int32_t lattice_level);

// Bfr::Surface<double> (approximation level `approx_level`) at each (face, u, v).
LimitPoints limit_at(ControlCage const& cage, rust::Slice<const uint32_t> faces, rust::Slice<const double> uv,
                     int32_t approx_level);

}  // namespace osd
}  // namespace voxelkit
