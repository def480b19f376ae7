//! What a job reports: one serde struct, printed as JSON (`--json`, the Python module's
//! `report` dict) or as the human summary, so both always say the same.

use crate::progress::StageTime;
use crate::solids::winding_inside::AMBIGUOUS;
use serde::Serialize;

/// A mesh written from a grid.
#[derive(Serialize, Debug, Clone, Default)]
pub struct MeshWritten {
    pub file: String,
    pub vertices: u64,
    pub triangles: u64,
    /// With adaptivity: what merging flat regions started from.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub merged: Option<Merged>,
    /// Remeshing: the largest distance from the mesh to its source and from the source to
    /// it (world units).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub distance_to_source: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub source_to_mesh: Option<f64>,
}

/// A mesh's flat regions merged: the triangles before, and the bound (voxels).
#[derive(Serialize, Debug, Clone, Copy)]
pub struct Merged {
    pub triangles_before_merging: u64,
    pub adaptivity: f64,
}

impl MeshWritten {
    /// The file and its counts, and what merging flat regions left of the triangles.
    pub fn describe(&self) -> String {
        let merged = self.merged.map_or(String::new(), |m| {
            format!(
                "; {} before flat regions were merged within {} voxels",
                m.triangles_before_merging, m.adaptivity
            )
        });
        format!(
            "{} ({} vertices, {} triangles, closed and manifold{merged})",
            self.file, self.vertices, self.triangles
        )
    }
}

/// The report of one job. Every number is a number; `seconds` is the whole run.
#[derive(Serialize, Debug, Clone, Default)]
pub struct Report {
    /// The file written, once written (`-` for standard output).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub output: Option<String>,
    /// The input file or a description of the input (shape, formula, arrays).
    pub input: String,
    /// The preview picture written beside the output (`--preview`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preview: Option<String>,
    /// The mesh of the result's surface written beside it (`--mesh-out`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mesh: Option<MeshWritten>,
    /// The method, as written to the `.vdb` metadata.
    pub method: String,
    /// Voxels of the main grid (the surface, or the whole solid).
    pub voxels: u64,
    /// 8x8x8 leaves holding them.
    pub leaves: u64,
    pub voxel_size: f64,
    /// World position of the centre of voxel (0,0,0).
    pub origin: [f64; 3],
    /// Within bounds: the index box of the voxels kept (both corners inclusive), and the
    /// voxels left out; the details other than a solid's or a band's measures count the
    /// work before the cut.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bounds_voxels: Option<[[i64; 3]; 2]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub voxels_outside_bounds: Option<u64>,
    #[serde(flatten)]
    pub details: Details,
    /// The mesh attributes written as grids: name, how they were carried, voxels.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub attributes: Vec<String>,
    /// What the user should know although the job succeeded.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// Where the time went: reading and planning, each stage of the work, writing.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub stages: Vec<StageTime>,
    /// Time in the voxelization (or classification) itself.
    pub voxelize_seconds: f64,
    /// The whole run: reading, planning, voxelizing, measuring and writing.
    pub seconds: f64,
    /// Peak resident memory of the process, and what planning estimated.
    pub peak_mib: f64,
    pub estimated_mib: f64,
}

/// What each kind of job adds to the report.
#[derive(Serialize, Debug, Clone, Default)]
#[serde(untagged)]
pub enum Details {
    #[default]
    None,
    Separating {
        separability: u32,
        classes: SeparatingClasses,
    },
    Projective(ProjectiveDetails),
    SeparationCheck(SeparationCheckDetails),
    Shape {
        shape: String,
        separability: u32,
        /// Whether the slabs carry the margin for curvature that the separation proof needs on
        /// curved surfaces (off: the paper's plain slabs, which can leave holes).
        curvature_margin: bool,
        /// Formulas: voxels added where interval arithmetic could not prove a step between two
        /// centres left out free of the surface (`step_certificate`).
        #[serde(skip_serializing_if = "Option::is_none")]
        certificate_voxels: Option<u64>,
    },
    Subdivision(SubdivisionDetails),
    Implicit(ImplicitDetails),
    Solid(SolidDetails),
    DistanceBand(DistanceBandDetails),
    DepthLayers(DepthLayerDetails),
    Csg(CsgDetails),
    BrickFaces(BrickFaceDetails),
}

/// A brick's outside components, and their labels on its faces.
#[derive(Serialize, Debug, Clone, Default)]
pub struct BrickFaceDetails {
    pub outside_components: u32,
    /// The labels on the six faces (see `bricks::FACES`) as runs, for the client's join; 0 on
    /// the surface.
    #[serde(skip)]
    pub labels: Vec<super::brick_exterior::FaceRuns>,
}

/// Voxels by the part of Huang et al.'s criterion that first produced them.
#[derive(Serialize, Debug, Clone, Default)]
pub struct SeparatingClasses {
    pub vertex_voxels: u64,
    pub edge_voxels: u64,
    pub body_voxels: u64,
    pub triangles: u64,
    pub edges: u64,
    pub vertices: u64,
    /// Faces without area (or with a repeated vertex), voxelized by their edges only.
    pub degenerate_faces: u64,
}

#[derive(Serialize, Debug, Clone, Default)]
pub struct SeparationCheckDetails {
    pub separability: u32,
    /// Voxel centres inside the mesh (by ray parity), the empty voxels the exterior flood
    /// reached, and the inside centres among them: zero for a separating surface.
    pub inside_centres: u64,
    pub exterior_voxels: u64,
    pub leaked: u64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_leak: Option<[i64; 3]>,
    /// Surface voxels whose removal changes no topology (Huang et al.'s minimality).
    pub simple_voxels: u64,
    pub simple_share: f64,
    /// The resolution, for the summary.
    #[serde(skip)]
    pub resolution: String,
}

#[derive(Serialize, Debug, Clone, Default)]
pub struct ProjectiveDetails {
    pub triangles: u64,
    /// Triangles without area, voxelized as their longest edge.
    pub degenerate_triangles: u64,
    pub segments: u64,
    pub color: String,
}

#[derive(Serialize, Debug, Clone, Default)]
pub struct SubdivisionDetails {
    pub adjacency: u32,
    /// Voxels crossed by two sheets of the surface with opposite normals.
    pub opposite_normal_voxels: u64,
    pub patches: u64,
    /// Limit-surface evaluations, and what a uniform grid at the same density would need.
    pub evaluations: u64,
    pub uniform_evaluations: u64,
    pub subpatches: u64,
    /// Sub-patches whose side fell below the paper's depth guard (1 / the extent in voxels)
    /// while their corner voxels were still not adjacent: accepted as they are, their corner
    /// voxels output (a sign of a degenerate patch, not of an error).
    pub depth_guard_stops: u64,
    /// Splits made only by `enclose` (a sub-patch whose bound left its corner voxels).
    pub enclose_splits: u64,
    /// With `enclose`: voxels added from sub-patch bounds smaller than the tolerance, where
    /// the surface grazes a voxel edge or corner no sample lands in (most hold a sample too).
    pub tolerance_voxels: u64,
    /// Limit-surface area summed over the final sub-patches, world units.
    pub area: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tags: Option<TagSummary>,
}

/// OpenSubdiv crease and corner tags applied to a control mesh, and the files they came from.
#[derive(Serialize, Debug, Clone, Default)]
pub struct TagSummary {
    pub creases: u64,
    pub corners: u64,
    pub from: Vec<String>,
}

impl TagSummary {
    /// `None` for a control mesh without tags.
    pub fn of(tags: &crate::subd::Tags) -> Option<TagSummary> {
        (!tags.is_empty()).then(|| TagSummary {
            creases: tags.creases.len() as u64,
            corners: tags.corners.len() as u64,
            from: tags
                .sources
                .iter()
                .map(|p| p.display().to_string())
                .collect(),
        })
    }

    /// The summary's words for `tags`, empty without any.
    fn phrase(tags: &Option<TagSummary>) -> String {
        tags.as_ref().map_or(String::new(), |t| {
            format!(
                "; {} creases and {} corners from {}",
                t.creases,
                t.corners,
                t.from.join(", ")
            )
        })
    }
}

#[derive(Serialize, Debug, Clone, Default)]
pub struct ImplicitDetails {
    pub formula: String,
    pub coordinates: String,
    /// Octree cells whose interval test was evaluated.
    pub cells_tested: u64,
    /// Cells on the axis of spherical or cylindrical coordinates (tested as a whole).
    pub axis_cells: u64,
    /// Levels written with `levels` (0 when only the finest is kept).
    pub levels: u64,
    pub depth: u32,
}

#[derive(Serialize, Debug, Clone, Default)]
pub struct DistanceBandDetails {
    /// Half width of the band in voxels; the background is band x voxel size.
    pub band: f64,
    pub signed: bool,
    /// Band voxels whose centre is inside (negative values).
    pub inside_band_voxels: u64,
    pub background: f64,
    /// The inside rule that signed the distances, and why (signed only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inside_rule: Option<String>,
    /// Centres whose winding number lies near 1/2 (written as `ambiguous`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ambiguous_voxels: Option<u64>,
}

#[derive(Serialize, Debug, Clone, Default)]
pub struct SolidDetails {
    pub inside_voxels: u64,
    pub surface_voxels: u64,
    pub volume_inside: f64,
    pub volume_with_surface: f64,
    pub density: f64,
    pub mass_inside: f64,
    pub mass_with_surface: f64,
    /// 26-connected components of surface plus inside (when counted).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub components: Option<u64>,
    /// Genus of the boundary, for solids without cavities: components - Euler characteristic.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub genus: Option<i64>,
    pub inside_rule: String,
    /// Centres whose winding number lies near 1/2 (written as `ambiguous`), where the
    /// winding number decided.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ambiguous_voxels: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mesh_signed_volume: Option<f64>,
    /// The surface's area: a mesh's, or a limit surface's by Gauss quadrature.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mesh_area: Option<f64>,
    /// The exact volume a Catmull-Clark limit surface encloses (Gauss quadrature).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limit_volume: Option<f64>,
    /// A Catmull-Clark control mesh's crease and corner tags.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tags: Option<TagSummary>,
    #[serde(skip_serializing_if = "Option::is_none", flatten)]
    pub flooding_xyz: Option<FloodingXyzDetails>,
}

/// Lai & Cheng's FloodingXYZ at work.
#[derive(Serialize, Debug, Clone, Copy, Default)]
pub struct FloodingXyzDetails {
    pub line_floods: u64,
    pub sweeps: u64,
    pub graystack_overflows: u64,
}

#[derive(Serialize, Debug, Clone, Default)]
pub struct DepthLayerDetails {
    pub inside_voxels: u64,
    /// Voxels no direction could decide (written as `unclassified`).
    pub unclassified_voxels: u64,
    /// Of those, the voxels on rays crossed an odd number of times (an open mesh).
    pub unclassified_on_odd_rays: u64,
    pub odd_rays: u64,
    pub boundary_edges: u64,
    pub non_manifold_edges: u64,
    pub volume: f64,
    pub volume_with_unclassified: f64,
    pub density: f64,
    pub mass: f64,
    /// A mesh's signed volume (none for a formula).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mesh_signed_volume: Option<f64>,
    pub directions: Vec<DirectionCounts>,
}

/// One direction's rays by how often they cross the mesh.
#[derive(Serialize, Debug, Clone, Default)]
pub struct DirectionCounts {
    pub direction: [i64; 3],
    pub rays: u64,
    pub crossed_0: u64,
    pub crossed_2: u64,
    pub crossed_4: u64,
    pub crossed_more: u64,
    pub crossed_odd: u64,
}

#[derive(Serialize, Debug, Clone, Default)]
pub struct CsgDetails {
    pub volume: f64,
    pub leaves_of_tree: Vec<CsgLeafCount>,
}

#[derive(Serialize, Debug, Clone, Default)]
pub struct CsgLeafCount {
    pub leaf: String,
    pub voxels: u64,
}

impl Report {
    /// Sets the whole run's time and the peak memory: the last thing before printing.
    pub fn finish(&mut self, start: std::time::Instant) {
        self.seconds = start.elapsed().as_secs_f64();
        self.peak_mib = crate::system::peak_memory_mib();
    }

    /// The report as one JSON object.
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("a report serializes")
    }

    /// The human summary: a first line with what was made, then details.
    pub fn summary(&self) -> String {
        let place = self.output.as_deref().unwrap_or(&self.input);
        let timing = format!(
            "{:.2} s (voxelize {:.2} s), peak {:.0} MiB",
            self.seconds, self.voxelize_seconds, self.peak_mib
        );
        let mut text = match &self.details {
            Details::None => format!(
                "{place}: {} voxels in {} leaves ({}), voxel size {:.6}, {timing}",
                self.voxels, self.leaves, self.method, self.voxel_size
            ),
            Details::Separating {
                separability,
                classes: c,
            } => format!(
                "{place}: {} voxels ({} vertex, {} edge, {} body) in {} leaves, {separability}-separating, voxel size {:.6}, {timing}",
                self.voxels,
                c.vertex_voxels,
                c.edge_voxels,
                c.body_voxels,
                self.leaves,
                self.voxel_size
            ),
            Details::Projective(p) => {
                let rate = |n: u64| n as f64 / self.voxelize_seconds.max(1e-9) / 1e6;
                let primitives = if p.segments > 0 {
                    format!("{} segments ({:.2}M lines/s)", p.segments, rate(p.segments))
                } else {
                    format!(
                        "{} triangles ({} without area, voxelized as their longest edge; {:.2}M triangles/s)",
                        p.triangles,
                        p.degenerate_triangles,
                        rate(p.triangles)
                    )
                };
                format!(
                    "{place}: {} voxels in {} leaves from {primitives}, colour {}, voxel size {:.6}, {timing}",
                    self.voxels, self.leaves, p.color, self.voxel_size
                )
            }
            Details::SeparationCheck(c) => format!(
                "{} at {}: {} voxels, {}-separating: exterior flood ({}-connected) reached {} inside voxels of {} ({}); {} simple voxels ({:.2}%)",
                self.input,
                c.resolution,
                self.voxels,
                c.separability,
                c.separability,
                c.leaked,
                c.inside_centres,
                if c.leaked == 0 {
                    "separating"
                } else {
                    "NOT separating"
                },
                c.simple_voxels,
                100.0 * c.simple_share
            ),
            Details::Shape {
                shape,
                separability,
                curvature_margin,
                certificate_voxels,
            } => format!(
                "{place}: {shape}: {} voxels in {} leaves, {}, voxel size {:.6}, {timing}",
                self.voxels,
                self.leaves,
                match (curvature_margin, certificate_voxels) {
                    (_, Some(added)) => format!(
                        "{separability}-separating (every step between two centres left out \
                         proven free of the surface by interval arithmetic; {added} voxel(s) \
                         added where it could not be{})",
                        if *curvature_margin {
                            ""
                        } else {
                            ", the paper's plain slabs"
                        }
                    ),
                    (true, None) => format!("{separability}-separating"),
                    (false, None) => format!(
                        "the paper's plain {separability}-separating slabs without the curvature \
                         margin (separation not guaranteed on a curved surface)"
                    ),
                },
                self.voxel_size
            ),
            Details::Subdivision(s) => format!(
                "{place}: {} voxels ({} crossed by opposite sheets) from {} patches; {} evaluations \
                 (a uniform grid at the same density: {}), {} sub-patches ({} stopped by the depth \
                 guard, {} tolerance voxels); area {:.6}; {}-adjacent{}; voxel size {:.6}, {timing}",
                self.voxels,
                s.opposite_normal_voxels,
                s.patches,
                s.evaluations,
                s.uniform_evaluations,
                s.subpatches,
                s.depth_guard_stops,
                s.tolerance_voxels,
                s.area,
                s.adjacency,
                TagSummary::phrase(&s.tags),
                self.voxel_size
            ),
            Details::Implicit(s) => format!(
                "{place}: {} voxels at depth {} ({} cells tested, {} on the axis){}; voxel size {:.6}, {timing}",
                self.voxels,
                s.depth,
                s.cells_tested,
                s.axis_cells,
                if s.levels == 0 {
                    String::new()
                } else {
                    format!(", {} levels", s.levels)
                },
                self.voxel_size
            ),
            Details::Solid(s) => solid_summary(place, s, &timing),
            Details::DistanceBand(d) => format!(
                "{place}: {} {} distances within {} voxels ({} inside), background {:.6}, voxel size {:.6}{}, {timing}",
                self.voxels,
                if d.signed { "signed" } else { "unsigned" },
                d.band,
                d.inside_band_voxels,
                d.background,
                self.voxel_size,
                inside_summary(d.inside_rule.as_deref(), d.ambiguous_voxels)
            ),
            Details::DepthLayers(d) => depth_layer_summary(place, &self.method, d, &timing),
            Details::BrickFaces(b) => format!(
                "{place}: {} surface voxels, {} outside components, {timing}",
                self.voxels, b.outside_components
            ),
            Details::Csg(c) => {
                let mut t = format!(
                    "{place}: {} voxels (volume {:.6}) at voxel size {:.6} from {} leaves; {timing}",
                    self.voxels,
                    c.volume,
                    self.voxel_size,
                    c.leaves_of_tree.len()
                );
                for l in &c.leaves_of_tree {
                    t.push_str(&format!("\n  {:>12} voxels  {}", l.voxels, l.leaf));
                }
                t
            }
        };
        if let Some(p) = &self.preview {
            text.push_str(&format!("\npreview: {p}"));
        }
        if let Some(m) = &self.mesh {
            text.push_str(&format!("\nmesh: {}", m.describe()));
            if let (Some(to), Some(from)) = (m.distance_to_source, m.source_to_mesh) {
                text.push_str(&format!(
                    "\n  two-sided distance to the input: mesh to input {to:.6} ({:.3} voxels), \
                     input to mesh {from:.6} ({:.3} voxels)",
                    to / self.voxel_size,
                    from / self.voxel_size
                ));
            }
        }
        if !self.stages.is_empty() {
            let each: Vec<String> = self
                .stages
                .iter()
                .map(|s| {
                    format!(
                        "{} {:.2} s ({:.1} threads busy)",
                        s.stage, s.seconds, s.threads_busy
                    )
                })
                .collect();
            text.push_str(&format!("\nstages: {}", each.join(", ")));
        }
        if let (Some([lo, hi]), Some(out)) = (self.bounds_voxels, self.voxels_outside_bounds) {
            text.push_str(&format!(
                "\nwithin bounds: voxels {lo:?} to {hi:?} kept, {out} outside left out"
            ));
        }
        if !self.attributes.is_empty() {
            text.push_str(&format!("\nattributes: {}", self.attributes.join(", ")));
        }
        for w in &self.warnings {
            text.push_str(&format!("\nwarning: {w}"));
        }
        text
    }
}

/// `; inside: RULE (N ambiguous voxels)`, or nothing without a rule.
fn inside_summary(rule: Option<&str>, ambiguous: Option<u64>) -> String {
    let Some(rule) = rule else {
        return String::new();
    };
    match ambiguous {
        Some(n) => format!("; inside: {rule}; {n} voxels within {AMBIGUOUS} of winding number 1/2"),
        None => format!("; inside: {rule}"),
    }
}

fn solid_summary(place: &str, s: &SolidDetails, timing: &str) -> String {
    let mesh = match (s.mesh_signed_volume, s.mesh_area, s.limit_volume) {
        (_, Some(a), Some(v)) => format!(
            " (limit surface, Gauss quadrature: area {a:.6}, volume {v:.6}{})",
            TagSummary::phrase(&s.tags)
        ),
        (Some(v), Some(a), None) => format!(" (faces: area {a:.6}, signed volume {v:.6})"),
        (Some(v), None, None) => format!(" (mesh signed volume {v:.6})"),
        _ => String::new(),
    };
    let xyz = s.flooding_xyz.map_or(String::new(), |x| {
        format!(
            " (FloodingXYZ: {} line floods, {} sweeps, {} stack overflows)",
            x.line_floods, x.sweeps, x.graystack_overflows
        )
    });
    let topology = match (s.components, s.genus) {
        (Some(c), Some(g)) => format!("{c} component(s), genus {g}; "),
        _ => String::new(),
    };
    format!(
        "{place}{mesh}: {} inside + {} surface voxels; volume {:.6} (inside) .. {:.6} (with surface); \
         mass {:.6} .. {:.6} at density {}; {topology}{}{}{xyz}; {timing}",
        s.inside_voxels,
        s.surface_voxels,
        s.volume_inside,
        s.volume_with_surface,
        s.mass_inside,
        s.mass_with_surface,
        s.density,
        s.inside_rule,
        s.ambiguous_voxels.map_or(String::new(), |n| format!(
            " ({n} voxels within {AMBIGUOUS} of winding number 1/2)"
        ))
    )
}

fn depth_layer_summary(place: &str, method: &str, d: &DepthLayerDetails, timing: &str) -> String {
    let mut t = format!(
        "{place}: {method}: {} inside, {} unclassifiable voxels; volume {:.6} (inside centres){}; mass {:.6} at density {}{}",
        d.inside_voxels,
        d.unclassified_voxels,
        d.volume,
        if d.unclassified_voxels > 0 {
            format!(
                ", {:.6} with the unclassifiable voxels",
                d.volume_with_unclassified
            )
        } else {
            String::new()
        },
        d.mass,
        d.density,
        d.mesh_signed_volume
            .map(|v| format!("; mesh signed volume {v:.6}"))
            .unwrap_or_default()
    );
    t.push_str("\n  rays by crossings     0          2          4         >4        odd");
    for c in &d.directions {
        let name = format!("({},{},{})", c.direction[0], c.direction[1], c.direction[2]);
        t.push_str(&format!(
            "\n  {name:<12} {:>10} {:>10} {:>10} {:>10} {:>10}",
            c.crossed_0, c.crossed_2, c.crossed_4, c.crossed_more, c.crossed_odd
        ));
    }
    if d.odd_rays > 0 {
        t.push_str(&format!(
            "\n  the input is not closed ({} boundary and {} non-manifold edges): {} rays cross it an odd number of times, and the {} voxels on them are unclassifiable (written as `unclassified`, neither filled nor left empty)",
            d.boundary_edges, d.non_manifold_edges, d.odd_rays, d.unclassified_on_odd_rays
        ));
    } else if d.unclassified_voxels > 0 {
        t.push_str(&format!(
            "\n  {} voxels are crossed more than four times along every direction (with option `unclassified` paper: along some direction) and are written as `unclassified` (more directions, option `directions`, may decide some)",
            d.unclassified_voxels
        ));
    }
    t.push_str(&format!("\n  {timing}"));
    t
}
