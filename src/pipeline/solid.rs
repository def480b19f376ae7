//! The solid tasks: fill a mesh (exterior flood, depth layers, beams), its level set or
//! distance band, measure a mesh or a `.vdb` surface, evaluate a CSG tree; with volumes,
//! mass, components and genus.

use super::attribute_grids::{Carry, add_attributes};
use super::outcome::{Distances, Outcome};
use super::outcome::{provenance, tag_metadata};
use super::report::{
    CsgDetails, CsgLeafCount, DepthLayerDetails, Details, DirectionCounts, DistanceBandDetails,
    FloodingXyzDetails, SolidDetails, TagSummary,
};
use super::{Fill, SubdivisionFill};
use crate::contour::ExactSurface;
use crate::error::Result;
use crate::grid::{DenseMask, SparseGrid, Transform};
use crate::implicit::Formula;
use crate::io::vdb::{MetaValue, NORMAL_GRID, SHELL_GRID};
use crate::mesh::Aabb;
use crate::mesh::attributes::AttributeChoice;
use crate::mesh::segment_hits::MeshHits;
use crate::mesh::{GridFit, Mesh, index_box};
use crate::progress::Progress;
use crate::solids::beam::{BeamFill, beam_solid};
use crate::solids::csg_exact::ExactTree;
use crate::solids::csg_tree::CsgTree;
use crate::solids::depth_layers::{
    DepthLayerOptions, DepthLayerSolid, DepthLayerStats, Layers, depth_layer_solid, depth_layers_of,
};
use crate::solids::exterior_flood::{FloodMethod, Solid};
use crate::solids::flooded_mesh::{self, SurfaceAndInside};
use crate::solids::formula_rays::FormulaRays;
use crate::solids::inside_rule::{Inside, InsideChoice, InsideRule};
use crate::solids::level_set::{level_set, unsigned_distance};
use crate::solids::subdivision::{self, Filled};
use crate::subd::ControlMesh;
use crate::voxelize::parametric::ParametricOptions;
use rayon::prelude::*;
use std::sync::Arc;
use std::time::Instant;

/// What inside means for the exterior flood.
const FLOOD_RULE: &str =
    "inside = what the exterior flood (from the box corner, no normals needed) cannot reach";

/// What inside means for the winding number.
const WINDING_RULE: &str =
    "inside = the surface and the centres whose winding number is at least 1/2";

/// The report's rule for a flood solid decided by `choice`.
fn flood_rule(choice: &InsideChoice) -> String {
    let rule = match choice.inside {
        Inside::Winding(_) => WINDING_RULE,
        Inside::Parity => FLOOD_RULE,
    };
    format!("{rule} ({})", choice.reason)
}

/// The metadata naming the inside rule that ran and why.
fn inside_meta(meta: &mut Vec<(&str, MetaValue)>, choice: &InsideChoice) {
    meta.push(("inside_rule", choice.name().into()));
    meta.push(("inside_reason", choice.reason.clone().into()));
}

/// What inside means for a Catmull-Clark solid.
const SUBDIVISION_RULE: &str = "inside = what FloodingXYZ reaches from the seeds one voxel against the limit normals (Lai & Cheng)";

/// What inside means for the beams, by fill.
const BEAM_RULE: &str = "inside = the beams between front and back faces along z (centres between crossings 1-2, 3-4, ...)";
const BEAM_PAPER_RULE: &str = "inside = the beams along z from each back-face voxel up to the next front-face voxel (Jegathese et al.)";

/// The report of a surface and the solid inside it (with components and genus when
/// `with_topology`).
fn solid_details(
    whole: &SparseGrid,
    solid: &Solid,
    density: f64,
    rule: &str,
    mesh: Option<&Mesh>,
    with_topology: bool,
) -> Result<SolidDetails> {
    let m = solid.measures;
    let (components, genus) = if with_topology {
        let (c, g) = flooded_mesh::topology(whole)?;
        (Some(c), Some(g))
    } else {
        (None, None)
    };
    let (mass_inside, mass_with_surface) = m.mass(density);
    Ok(SolidDetails {
        inside_voxels: m.inside_voxels,
        surface_voxels: m.surface_voxels,
        volume_inside: m.volume_inside,
        volume_with_surface: m.volume_with_surface,
        density,
        mass_inside,
        mass_with_surface,
        components,
        genus,
        inside_rule: rule.to_string(),
        ambiguous_voxels: None,
        mesh_signed_volume: mesh.map(Mesh::signed_volume),
        mesh_area: None,
        limit_volume: None,
        tags: None,
        flooding_xyz: solid.xyz_stats.map(|s| FloodingXyzDetails {
            line_floods: s.line_floods,
            sweeps: s.sweeps,
            graystack_overflows: s.overflows,
        }),
    })
}

/// A surface plus the voxels inside it: `density` on both, `shell` and `interior` apart.
/// `describe` reports on the whole solid.
fn surface_and_inside(
    parts: SurfaceAndInside,
    meta: Vec<(&str, MetaValue)>,
    describe: impl FnOnce(&SparseGrid, &Solid) -> Result<SolidDetails>,
) -> Result<Outcome> {
    let SurfaceAndInside {
        surface,
        solid,
        whole,
        ambiguous,
    } = parts;
    let mut details = describe(&whole, &solid)?;
    details.ambiguous_voxels = ambiguous.as_ref().map(SparseGrid::voxel_count);
    let outcome = Outcome::new(whole, meta, Details::Solid(details))
        .with(SHELL_GRID, surface)
        .with("interior", solid.inside);
    Ok(with_ambiguous(outcome, ambiguous))
}

/// The outcome with its ambiguous centres as a grid `ambiguous`, where there are any.
fn with_ambiguous(outcome: Outcome, ambiguous: Option<SparseGrid>) -> Outcome {
    match ambiguous {
        Some(grid) if !grid.is_empty() => outcome.with("ambiguous", grid),
        _ => outcome,
    }
}

/// A solid classified at voxel centres: `shell` (voxels with a face towards the
/// outside) and `interior` beside the whole.
fn centre_solid(
    solid: &DenseMask,
    t: Transform,
    meta: Vec<(&str, MetaValue)>,
    details: Details,
) -> Outcome {
    let outer = solid.boundary();
    let interior = solid.minus(&outer).to_grid(t);
    Outcome::new(solid.to_grid(t), meta, details)
        .with(SHELL_GRID, outer.to_grid(t))
        .with("interior", interior)
}

/// What a mesh's solid is asked for.
pub(super) struct SolidAsked {
    pub fill: Fill,
    pub density: f64,
    pub topology: bool,
    pub inside: InsideRule,
}

pub(super) fn mesh_solid(
    mesh: &Mesh,
    t: Transform,
    asked: SolidAsked,
    fit: GridFit,
    progress: &Progress,
) -> Result<Outcome> {
    let SolidAsked {
        fill,
        density,
        topology,
        inside,
    } = asked;
    let start = Instant::now();
    let source = mesh.source.display().to_string();
    let meta = |method: &str| provenance(method, &source, fit);
    let outcome = match fill {
        Fill::Flood(flood) => {
            let (choice, parts) = flooded_mesh::flooded_mesh(mesh, t, flood, inside, progress)?;
            let mut method = meta(match choice.inside {
                Inside::Winding(_) => "huang-26-separating-surface+winding-number",
                Inside::Parity => "huang-26-separating-surface+exterior-flood",
            });
            inside_meta(&mut method, &choice);
            let rule = flood_rule(&choice);
            surface_and_inside(parts, method, |whole, solid| {
                solid_details(whole, solid, density, &rule, Some(mesh), topology)
            })?
        }
        Fill::Beam(fill) => {
            let beam = beam_solid(mesh, t, fill, progress)?;
            let (name, rule) = match fill {
                BeamFill::Parity => ("projective-beam", BEAM_RULE),
                BeamFill::Paper => ("projective-beam-paper", BEAM_PAPER_RULE),
            };
            let mut method = meta(name);
            method.push(("color", "none".into()));
            let parts = SurfaceAndInside::of(beam.surface, beam.solid);
            let mut outcome = surface_and_inside(parts, method, |whole, solid| {
                solid_details(whole, solid, density, rule, Some(mesh), topology)
            })?;
            if beam.unclosed_beams > 0 {
                outcome.report.warnings.push(format!(
                    "{} beams opened by a back face were not closed by a front face in their column and were left empty",
                    beam.unclosed_beams
                ));
            }
            outcome
        }
        Fill::DepthLayers(options) => {
            let edges = mesh.edge_counts();
            let region = index_box(&mesh.bbox(), &t);
            let solid = depth_layer_solid(mesh, &t, region, &options, progress)?;
            let mut details = depth_layer_details(&solid.stats, t, density);
            details.boundary_edges = edges.boundary;
            details.non_manifold_edges = edges.non_manifold;
            details.mesh_signed_volume = Some(mesh.signed_volume());
            depth_layer_outcome(solid, t, meta(&depth_layer_method(&options)), details)
        }
    };
    Ok(outcome.timed(start))
}

/// The report of a depth-layer solid (the input's edges and volume left to the caller).
fn depth_layer_details(s: &DepthLayerStats, t: Transform, density: f64) -> DepthLayerDetails {
    let cell = t.voxel_size.powi(3);
    let volume = s.inside_voxels as f64 * cell;
    DepthLayerDetails {
        inside_voxels: s.inside_voxels,
        unclassified_voxels: s.unclassified_voxels,
        unclassified_on_odd_rays: s.open_voxels,
        odd_rays: s.odd_rays(),
        boundary_edges: 0,
        non_manifold_edges: 0,
        volume,
        volume_with_unclassified: (s.inside_voxels + s.unclassified_voxels) as f64 * cell,
        density,
        mass: volume * density,
        mesh_signed_volume: None,
        directions: s
            .per_direction
            .iter()
            .map(|c| DirectionCounts {
                direction: c.direction,
                rays: c.rays,
                crossed_0: c.none,
                crossed_2: c.two,
                crossed_4: c.four,
                crossed_more: c.more,
                crossed_odd: c.odd,
            })
            .collect(),
    }
}

/// The method name of depth layers with `options`.
fn depth_layer_method(options: &DepthLayerOptions) -> String {
    format!(
        "depth-layers ({}, {} directions)",
        match options.layers {
            Layers::Double => "double layers + stencil",
            Layers::Single => "single layer",
        },
        options.directions.len()
    )
}

/// A depth-layer solid as an outcome: its inside voxels, shell, interior and unclassifiable
/// voxels.
fn depth_layer_outcome(
    solid: DepthLayerSolid,
    t: Transform,
    meta: Vec<(&str, MetaValue)>,
    details: DepthLayerDetails,
) -> Outcome {
    centre_solid(&solid.inside, t, meta, Details::DepthLayers(details))
        .with("unclassified", solid.unclassified.to_grid(t))
}

/// A formula's solid, F < 0 within `[min, max]`, by double depth layers along z, x and y, each
/// ray's crossings isolated by interval arithmetic (`solids::formula_rays`).
pub(super) fn formula_depth_layers(
    formula: &Formula,
    text: &str,
    bounds: Aabb,
    t: Transform,
    progress: &Progress,
) -> Result<Outcome> {
    let start = Instant::now();
    let region = index_box(&bounds, &t);
    let options = DepthLayerOptions::default();
    let rays = FormulaRays {
        formula,
        transform: t,
        first: region.min,
        bounds,
        progress,
    };
    let solid = depth_layers_of(&rays, region, &options, progress)?;
    let details = depth_layer_details(&solid.stats, t, 1.0);
    let method = depth_layer_method(&options);
    let coordinates = format!("{:?}", formula.coordinates).to_lowercase();
    let meta = vec![
        ("method", method.as_str().into()),
        ("formula", text.into()),
        ("coordinates", coordinates.as_str().into()),
    ];
    Ok(depth_layer_outcome(solid, t, meta, details).timed(start))
}

/// What a distance band job asks for.
pub(super) struct BandAsked<'a> {
    /// Half width in voxels.
    pub band: f64,
    pub signed: bool,
    pub inside: InsideRule,
    pub attributes: &'a AttributeChoice,
}

pub(super) fn distance_band(
    mesh: &Arc<Mesh>,
    t: Transform,
    asked: BandAsked,
    fit: GridFit,
    progress: &Progress,
) -> Result<Outcome> {
    let start = Instant::now();
    let BandAsked {
        band,
        signed,
        inside,
        attributes,
    } = asked;
    // Unsigned distances have no inside.
    let (grid, interior, choice, ambiguous, inside_band_voxels) = if signed {
        let (choice, set) = level_set(mesh, t, band, inside, progress)?;
        let ambiguous = matches!(choice.inside, Inside::Winding(_)).then_some(set.ambiguous);
        let inside_band_voxels = set.inside_band_voxels;
        (
            set.band,
            Some(set.interior),
            Some(choice),
            ambiguous,
            inside_band_voxels,
        )
    } else {
        let grid = unsigned_distance(mesh, t, band, progress)?;
        (grid, None, None, None, 0)
    };
    let background = band * t.voxel_size;
    let method = if signed {
        "exact-signed-distance-band"
    } else {
        "exact-unsigned-distance-band"
    };
    let mut meta = provenance(method, &mesh.source.display().to_string(), fit);
    meta.push(("band_voxels", band.into()));
    if let Some(choice) = &choice {
        inside_meta(&mut meta, choice);
    }
    let details = DistanceBandDetails {
        band,
        signed,
        inside_band_voxels,
        background,
        inside_rule: choice
            .as_ref()
            .map(|c| format!("{} ({})", c.name(), c.reason)),
        ambiguous_voxels: ambiguous.as_ref().map(SparseGrid::voxel_count),
    };
    let mut outcome = Outcome::new(grid, meta, Details::DistanceBand(details));
    if signed {
        outcome.exact = Some(Arc::new(MeshHits::new(Arc::clone(mesh))));
    }
    outcome.distances = Some(Distances {
        background: background as f32,
        interior,
    });
    add_attributes(&mut outcome, mesh, attributes, Carry::Nearest, progress)?;
    Ok(with_ambiguous(outcome, ambiguous).timed(start))
}

/// Band voxels whose centre is inside (negative distances).
pub(super) fn inside_band_voxels(band: &SparseGrid) -> u64 {
    band.leaves()
        .par_iter()
        .map(|l| {
            let values = l.value.as_ref().expect("distances");
            l.offsets().filter(|&n| values[n] < 0.0).count() as u64
        })
        .sum()
}

pub(super) fn measure_mesh(
    mesh: &Mesh,
    t: Transform,
    flood: FloodMethod,
    density: f64,
    inside: InsideRule,
    progress: &Progress,
) -> Result<Outcome> {
    let start = Instant::now();
    let (choice, parts) = flooded_mesh::flooded_mesh(mesh, t, flood, inside, progress)?;
    let mut meta = vec![
        (
            "method",
            match choice.inside {
                Inside::Winding(_) => "huang-26-separating-surface+winding-number",
                Inside::Parity => "huang-26-separating-surface+exterior-flood",
            }
            .into(),
        ),
        ("source_file", mesh.source.display().to_string().into()),
    ];
    inside_meta(&mut meta, &choice);
    let rule = flood_rule(&choice);
    let outcome = surface_and_inside(parts, meta, |whole, solid| {
        let details = solid_details(whole, solid, density, &rule, Some(mesh), true)?;
        Ok(SolidDetails {
            mesh_area: Some(mesh.area()),
            ..details
        })
    })?;
    Ok(outcome.timed(start))
}

pub(super) fn measure_surface(
    surface: &SparseGrid,
    source: &str,
    flood: FloodMethod,
    density: f64,
    progress: &Progress,
) -> Result<Outcome> {
    let start = Instant::now();
    let parts = SurfaceAndInside::flooded(surface.clone(), flood, progress)?;
    let meta = vec![
        ("method", "exterior-flood".into()),
        ("source_file", source.into()),
    ];
    let outcome = surface_and_inside(parts, meta, |whole, solid| {
        solid_details(whole, solid, density, FLOOD_RULE, None, true)
    })?;
    Ok(outcome.timed(start))
}

pub(super) fn csg_tree(tree: &CsgTree, progress: &Progress) -> Result<Outcome> {
    let start = Instant::now();
    let (t, solid, leaves) = tree.evaluate()?;
    progress.advance(tree.node_count() as u64);
    let details = CsgDetails {
        volume: solid.count() as f64 * t.voxel_size.powi(3),
        leaves_of_tree: leaves
            .into_iter()
            .map(|l| CsgLeafCount {
                leaf: l.what,
                voxels: l.voxels,
            })
            .collect(),
    };
    let meta = vec![
        ("method", "csg-tree (voxel centres)".into()),
        ("source_file", tree.source.display().to_string().into()),
    ];
    let mut outcome = centre_solid(&solid, t, meta, Details::Csg(details));
    if let Some(exact) = ExactTree::of(tree, &t) {
        let normals = outcome
            .extra
            .iter()
            .find(|(name, _)| name == SHELL_GRID)
            .map(|(_, shell)| exact.normals_on(shell));
        if let Some(normals) = normals {
            outcome = outcome.with(NORMAL_GRID, normals);
        }
        outcome.exact = Some(Arc::new(exact) as Arc<dyn ExactSurface>);
    }
    Ok(outcome.timed(start))
}

/// Lai & Cheng's Catmull-Clark solid: the limit surface, the inside flooded from seeds by
/// FloodingXYZ, and the exact limit volume and area beside the voxel volume.
pub(super) fn subdivision_solid(
    control: &ControlMesh,
    t: Transform,
    options: &ParametricOptions,
    fill: SubdivisionFill,
    fit: GridFit,
    memory: u64,
    progress: &Progress,
) -> Result<Outcome> {
    let start = Instant::now();
    let made = if fill.depth_layers {
        subdivision::subdivision_depth_layer_solid(control, t, options, memory, progress)?
    } else {
        subdivision::subdivision_solid(control, t, options, fill.graystack.max(1), progress)?
    };
    // How the inside was found names the method, its metadata and the summary's rule.
    let (method, filled_meta, rule): (_, Vec<(&str, MetaValue)>, _) = match made.filled {
        Filled::Seeds {
            seeds,
            outside_seeds,
        } => (
            "lai-cheng-parametric-enclosed+seeds+flooding-xyz",
            // Steps along tilted normals can leave the solid; their floods reach the border
            // and are dropped (`solids::subdivision`).
            vec![
                ("seeds", seeds.into()),
                ("outside_seeds", outside_seeds.into()),
            ],
            SUBDIVISION_RULE.to_string(),
        ),
        Filled::DepthLayers {
            triangles,
            deepest,
            stats,
            by_winding_number,
        } => (
            "lai-cheng-parametric-enclosed+depth-layers-on-certified-tessellation",
            vec![
                ("tessellation_triangles", triangles.into()),
                ("tessellation_deepest_level", deepest.into()),
                (
                    "tessellation_tolerance_voxels",
                    subdivision::TESSELLATION_TOLERANCE.into(),
                ),
                ("odd_rays", stats.odd_rays().into()),
                ("decided_by_winding_number", by_winding_number.into()),
            ],
            format!(
                "inside = the centres double depth layers along {} directions put inside, on a \
                 tessellation within {} voxel of the limit surface ({triangles} triangles), \
                 {by_winding_number} of them settled by its winding number where no direction \
                 decided; and the enclosing surface",
                stats.per_direction.len(),
                subdivision::TESSELLATION_TOLERANCE
            ),
        ),
    };
    let mut meta = provenance(method, &control.source.display().to_string(), fit);
    meta.push(("adjacency", options.adjacency.number().into()));
    meta.push(("limit_volume", made.limit_volume.into()));
    meta.push(("limit_area", made.limit_area.into()));
    meta.extend(filled_meta);
    let tags = TagSummary::of(&control.tags);
    tag_metadata(&mut meta, &tags);
    let (limit_volume, limit_area) = (made.limit_volume, made.limit_area);
    let opposite = made.surface.opposite;
    let parts = SurfaceAndInside::of(made.surface.surface, made.solid);
    let outcome = surface_and_inside(parts, meta, |whole, solid| {
        let mut details = solid_details(whole, solid, fill.density, &rule, None, fill.topology)?;
        details.limit_volume = Some(limit_volume);
        details.mesh_area = Some(limit_area);
        details.tags = tags.clone();
        Ok(details)
    })?;
    Ok(outcome.with("opposite_normals", opposite).timed(start))
}
