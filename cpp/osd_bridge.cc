// OpenSubdiv's limit points for voxelkit's live checks (see osd_bridge.h).
#include "voxelkit/cpp/osd_bridge.h"
#include "voxelkit/src/ffi/osd.rs.h"

#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>
#include <opensubdiv/far/error.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <cmath>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

using namespace OpenSubdiv;

namespace voxelkit {
namespace osd {
namespace {

// The vertex type PrimvarRefiner interpolates.
struct Point3 {
    double p[3];
    void Clear() { p[0] = p[1] = p[2] = 0.0; }
    void AddWithWeight(Point3 const& src, double w) {
        for (int k = 0; k < 3; ++k) p[k] += w * src.p[k];
    }
};

// OpenSubdiv reports topology errors through a global callback; keep the last message.
std::mutex error_mutex;
std::string last_error;
void record_error(Far::ErrorType, const char* message) {
    std::lock_guard<std::mutex> lock(error_mutex);
    last_error = message;
}

using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;

std::unique_ptr<Far::TopologyRefiner> make_refiner(ControlCage const& cage) {
    auto const& positions = cage.positions;
    auto const& face_sizes = cage.face_sizes;
    auto const& face_verts = cage.face_verts;
    if (positions.size() % 3 != 0) throw std::invalid_argument("positions must be x,y,z triples");
    const int vertex_count = static_cast<int>(positions.size() / 3);
    size_t corners = 0;
    for (int32_t n : face_sizes) {
        if (n < 3) throw std::invalid_argument("a face has fewer than 3 corners");
        corners += static_cast<size_t>(n);
    }
    if (corners != face_verts.size()) throw std::invalid_argument("face sizes do not match the corner list");
    for (int32_t v : face_verts) {
        if (v < 0 || v >= vertex_count) throw std::invalid_argument("a face corner is out of range");
    }
    if (cage.crease_verts.size() != 2 * cage.crease_weights.size() ||
        cage.corner_verts.size() != cage.corner_weights.size())
        throw std::invalid_argument("one sharpness per crease edge and per corner is needed");
    for (int32_t v : cage.crease_verts)
        if (v < 0 || v >= vertex_count) throw std::invalid_argument("a crease vertex is out of range");
    for (int32_t v : cage.corner_verts)
        if (v < 0 || v >= vertex_count) throw std::invalid_argument("a corner vertex is out of range");
    Sdc::Options sdc;
    sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
    Far::TopologyDescriptor desc;
    desc.numVertices = vertex_count;
    desc.numFaces = static_cast<int>(face_sizes.size());
    desc.numVertsPerFace = face_sizes.data();
    desc.vertIndicesPerFace = face_verts.data();
    desc.numCreases = static_cast<int>(cage.crease_weights.size());
    desc.creaseVertexIndexPairs = cage.crease_verts.data();
    desc.creaseWeights = cage.crease_weights.data();
    desc.numCorners = static_cast<int>(cage.corner_weights.size());
    desc.cornerVertexIndices = cage.corner_verts.data();
    desc.cornerWeights = cage.corner_weights.data();
    {
        std::lock_guard<std::mutex> lock(error_mutex);
        last_error.clear();
        Far::SetErrorCallback(record_error);
    }
    Far::TopologyRefiner* refiner = Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, sdc));
    if (!refiner) {
        std::lock_guard<std::mutex> lock(error_mutex);
        throw std::runtime_error("OpenSubdiv rejected the control mesh: " + last_error);
    }
    return std::unique_ptr<Far::TopologyRefiner>(refiner);
}

void push_point(LimitPoints& out, uint32_t face, double u, double v, const double* p, const double* du,
                const double* dv) {
    double n[3] = {du[1] * dv[2] - du[2] * dv[1], du[2] * dv[0] - du[0] * dv[2], du[0] * dv[1] - du[1] * dv[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    out.face.push_back(face);
    out.uv.push_back(u);
    out.uv.push_back(v);
    for (int k = 0; k < 3; ++k) {
        out.position.push_back(p[k]);
        out.normal.push_back(len > 0.0 ? n[k] / len : 0.0);
    }
}

// Sub-face tiles per row of an n-gon in Bfr's QUAD_SUBFACES parameterization.
int subface_tiles(int n) {
    if (n == 3) return 2;
    if (n >= 5 && n <= 9) return 3;
    return 1 + static_cast<int>(std::floor(std::sqrt(static_cast<double>(n - 1))));
}

// A refined face and where its corners lie in its base face's (u, v).
struct FaceDomain {
    uint32_t base;
    std::vector<double> u, v;
};

}  // namespace

LimitPoints limit_at_dyadic(ControlCage const& cage, int32_t level, int32_t lattice_level) {
    if (level < 1 || level > 8) throw std::invalid_argument("refinement level must be 1..8");
    if (lattice_level < 1 || lattice_level > level) throw std::invalid_argument("lattice level must be 1..level");
    auto const& positions = cage.positions;
    auto const& face_sizes = cage.face_sizes;
    auto refiner = make_refiner(cage);
    Far::TopologyRefiner::UniformOptions uniform(level);
    uniform.fullTopologyInLastLevel = true;  // vertex-face relations of the last level are read
    refiner->RefineUniform(uniform);

    std::vector<std::vector<Point3>> points(level + 1);
    points[0].resize(positions.size() / 3);
    for (size_t i = 0; i < points[0].size(); ++i)
        for (int k = 0; k < 3; ++k) points[0][i].p[k] = positions[3 * i + k];
    Far::PrimvarRefinerReal<double> primvar(*refiner);
    for (int l = 1; l <= level; ++l) {
        points[l].resize(refiner->GetLevel(l).GetNumVertices());
        Point3 const* src = points[l - 1].data();
        Point3* dst = points[l].data();
        primvar.Interpolate(l, src, dst);
    }

    // Base faces: quads carry their own (u, v); n-gons get them from their sub-faces.
    std::vector<FaceDomain> domains(face_sizes.size());
    for (size_t f = 0; f < face_sizes.size(); ++f) {
        domains[f].base = static_cast<uint32_t>(f);
        if (face_sizes[f] == 4) {
            domains[f].u = {0, 1, 1, 0};
            domains[f].v = {0, 0, 1, 1};
        }
    }
    for (int l = 1; l <= level; ++l) {
        Far::TopologyLevel const& parent = refiner->GetLevel(l - 1);
        Far::TopologyLevel const& child = refiner->GetLevel(l);
        std::vector<FaceDomain> next(child.GetNumFaces());
        for (int p = 0; p < parent.GetNumFaces(); ++p) {
            auto fv = parent.GetFaceVertices(p);
            auto fe = parent.GetFaceEdges(p);
            const int n = fv.size();
            FaceDomain const& pd = domains[p];
            for (int c : parent.GetFaceChildFaces(p)) {
                auto cv = child.GetFaceVertices(c);
                // Sub-face index of an n-gon's child: the corner whose vertex it holds.
                int s = 0;
                for (int k = 0; k < n; ++k)
                    for (int x : cv)
                        if (x == parent.GetVertexChildVertex(fv[k])) s = k;
                const int d = subface_tiles(n);
                const double tu = s % d, tv = s / d;
                FaceDomain cd{pd.base, {}, {}};
                for (int x : cv) {
                    double u = 0, v = 0;
                    if (n == 4) {
                        if (x == parent.GetFaceChildVertex(p)) {
                            u = 0.25 * (pd.u[0] + pd.u[1] + pd.u[2] + pd.u[3]);
                            v = 0.25 * (pd.v[0] + pd.v[1] + pd.v[2] + pd.v[3]);
                        }
                        for (int k = 0; k < 4; ++k) {
                            if (x == parent.GetVertexChildVertex(fv[k])) u = pd.u[k], v = pd.v[k];
                            if (x == parent.GetEdgeChildVertex(fe[k])) {
                                u = 0.5 * (pd.u[k] + pd.u[(k + 1) % 4]);
                                v = 0.5 * (pd.v[k] + pd.v[(k + 1) % 4]);
                            }
                        }
                    } else {
                        // Only at level 1: the sub-face's corners in its half-size tile.
                        if (x == parent.GetFaceChildVertex(p)) u = tu + 0.5, v = tv + 0.5;
                        if (x == parent.GetVertexChildVertex(fv[s])) u = tu, v = tv;
                        if (x == parent.GetEdgeChildVertex(fe[s])) u = tu + 0.5, v = tv;
                        if (x == parent.GetEdgeChildVertex(fe[(s + n - 1) % n])) u = tu, v = tv + 0.5;
                    }
                    cd.u.push_back(u);
                    cd.v.push_back(v);
                }
                next[c] = std::move(cd);
            }
        }
        domains = std::move(next);
    }

    Far::TopologyLevel const& last = refiner->GetLevel(level);
    std::vector<Point3> limit(last.GetNumVertices()), tan1(limit.size()), tan2(limit.size());
    primvar.Limit(points[level].data(), limit, tan1, tan2);
    LimitPoints out;
    for (int f = 0; f < last.GetNumFaces(); ++f) {
        auto fv = last.GetFaceVertices(f);
        for (int k = 0; k < fv.size(); ++k) {
            const int x = fv[k];
            // No exact reference at two kinds of vertex: Limit() gives an interior valence-2
            // vertex the corner mask, and at a boundary vertex with 3 or more faces its cross
            // tangent (Biermann et al.) is not an eigenvector of the crease rule, so the normal
            // it gives there changes with the refinement level.
            const int faces_here = last.GetVertexFaces(x).size();
            const bool boundary = last.IsVertexBoundary(x);
            if ((faces_here == 2 && !boundary) || (faces_here >= 3 && boundary)) continue;
            // Nor at vertices on tagged creases: Limit() gives a crease vertex one normal for
            // both sides, and a dart (a crease's end) the smooth masks, which are not its limit.
            bool tagged = !boundary && last.GetVertexSharpness(x) > 0.0f;
            for (int e : last.GetVertexEdges(x))
                tagged = tagged || (!last.IsEdgeBoundary(e) && last.GetEdgeSharpness(e) > 0.0f);
            if (tagged) continue;
            const double lattice = std::ldexp(1.0, lattice_level);
            const double u = domains[f].u[k] * lattice, v = domains[f].v[k] * lattice;
            if (u != std::floor(u) || v != std::floor(v)) continue;
            push_point(out, domains[f].base, domains[f].u[k], domains[f].v[k], limit[x].p, tan1[x].p,
                       tan2[x].p);
        }
    }
    return out;
}

LimitPoints limit_at(ControlCage const& cage, rust::Slice<const uint32_t> faces, rust::Slice<const double> uv,
                     int32_t approx_level) {
    if (uv.size() != 2 * faces.size()) throw std::invalid_argument("one (u, v) per face index is needed");
    auto const& positions = cage.positions;
    auto const& face_sizes = cage.face_sizes;
    auto refiner = make_refiner(cage);
    Bfr::SurfaceFactory::Options options;
    options.SetApproxLevelSmooth(approx_level).SetApproxLevelSharp(approx_level);
    Bfr::RefinerSurfaceFactory<> factory(*refiner, options);
    Bfr::Surface<double> surface;
    const Bfr::Surface<double>::PointDescriptor xyz(3);
    std::vector<double> patch_points;
    int64_t current = -1;
    LimitPoints out;
    for (size_t i = 0; i < faces.size(); ++i) {
        const uint32_t f = faces[i];
        if (f >= face_sizes.size()) throw std::invalid_argument("face index out of range");
        if (static_cast<int64_t>(f) != current) {
            if (!factory.InitVertexSurface(static_cast<int>(f), &surface) || !surface.IsValid())
                throw std::runtime_error("OpenSubdiv gives face " + std::to_string(f) + " no limit surface");
            patch_points.resize(static_cast<size_t>(surface.GetNumPatchPoints()) * 3);
            surface.PreparePatchPoints(positions.data(), xyz, patch_points.data(), xyz);
            current = f;
        }
        const double at[2] = {uv[2 * i], uv[2 * i + 1]};
        double p[3], du[3], dv[3];
        surface.Evaluate(at, patch_points.data(), xyz, p, du, dv);
        push_point(out, f, at[0], at[1], p, du, dv);
    }
    return out;
}

}  // namespace osd
}  // namespace voxelkit
