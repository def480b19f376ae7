//! Which inside a mesh gets, for every output that needs one (solids, level-set signs,
//! measures, CSG leaves). `winding`: the generalized winding number (`winding_inside`), defined
//! for any mesh; `parity`: ray parity and the exterior flood, defined for closed meshes only;
//! `auto`: the winding number wherever the orientation is consistent (open, overlapping, nested
//! or hollow meshes alike), parity where it is not, since a winding number sums orientations
//! and means nothing across an edge two faces use the same way.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::mesh::boundary_caps::{BoundaryCaps, boundary_caps};

/// The inside rule asked for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum InsideRule {
    /// The winding number where the orientation is consistent, parity where it is not.
    #[default]
    Auto,
    /// Inside where the generalized winding number is at least 1/2.
    Winding,
    /// Inside between crossings 2m and 2m+1 of a ray (closed meshes).
    Parity,
}

crate::named_choices! {
    InsideRule, "the inside rule":
    "auto" => Auto,
    "winding" => Winding,
    "parity" => Parity,
}

/// The rule that runs on one mesh, and why.
pub enum Inside {
    /// The winding number, with the caps that close the mesh.
    Winding(BoundaryCaps),
    Parity,
}

/// A rule that ran, for reports and metadata.
pub struct InsideChoice {
    pub inside: Inside,
    pub reason: String,
}

impl InsideChoice {
    /// `winding` or `parity`.
    pub fn name(&self) -> &'static str {
        match self.inside {
            Inside::Winding(_) => "winding",
            Inside::Parity => "parity",
        }
    }
}

/// The rule `rule` comes to on `mesh`; `why_closed` says what parity needs a closed mesh for.
pub fn choose_inside(rule: InsideRule, mesh: &Mesh, why_closed: &str) -> Result<InsideChoice> {
    let caps = boundary_caps(mesh);
    let inconsistent = caps.inconsistent_edges;
    let shape = if caps.is_empty() {
        "closed".to_string()
    } else {
        format!("open: {} hole loop(s)", caps.loops)
    };
    let choice = match rule {
        InsideRule::Parity => {
            mesh.require_closed(why_closed)?;
            InsideChoice {
                inside: Inside::Parity,
                reason: "parity, as asked".into(),
            }
        }
        InsideRule::Winding => InsideChoice {
            reason: if inconsistent > 0 {
                format!(
                    "winding, as asked, though {inconsistent} edge(s) are used twice the same way"
                )
            } else {
                format!("winding, as asked ({shape})")
            },
            inside: Inside::Winding(caps),
        },
        InsideRule::Auto if inconsistent == 0 => InsideChoice {
            reason: format!("winding: orientation consistent ({shape})"),
            inside: Inside::Winding(caps),
        },
        InsideRule::Auto => {
            if !mesh.edge_counts().is_closed() {
                return Err(Error::BadMesh(format!(
                    "{}: the mesh is open and {inconsistent} edge(s) are used twice the same way: \
                     a winding number means nothing where orientations disagree and parity needs \
                     a closed mesh; {why_closed}",
                    mesh.source.display()
                )));
            }
            InsideChoice {
                inside: Inside::Parity,
                reason: format!(
                    "parity: {inconsistent} edge(s) are used twice the same way (inconsistent orientation)"
                ),
            }
        }
    };
    Ok(choice)
}
