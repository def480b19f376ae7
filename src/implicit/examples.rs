//! Named formulas: the surfaces of Stolte & Kaufman's figures and two simple ones, for
//! `implicit --example`, `shape formula --example` and the benchmark of the paper's Fig. 7.

use super::Coordinates;
use crate::error::{Error, Result};

/// A named formula.
pub struct Example {
    pub name: &'static str,
    pub coordinates: Coordinates,
    pub formula: &'static str,
    pub about: &'static str,
    /// The paper's time for it at 512^3 (a 1999 workstation), where it gives one.
    pub paper_seconds_at_512: Option<f64>,
}

pub const EXAMPLES: [Example; 5] = [
    Example {
        name: "sphere",
        coordinates: Coordinates::Cartesian,
        formula: "x^2 + y^2 + z^2 - 0.8^2",
        about: "sphere of radius 0.8",
        paper_seconds_at_512: None,
    },
    Example {
        name: "torus",
        coordinates: Coordinates::Cartesian,
        formula: "(sqrt(x^2 + z^2) - 0.6)^2 + y^2 - 0.25^2",
        about: "torus around the y axis, radii 0.6 and 0.25",
        paper_seconds_at_512: None,
    },
    Example {
        name: "sinsin",
        coordinates: Coordinates::Spherical,
        formula: "sin(3*theta)*sin(4*phi) - r",
        about: "the paper's Fig. 6(a)",
        paper_seconds_at_512: None,
    },
    Example {
        name: "gear",
        coordinates: Coordinates::Cylindrical,
        formula: "teeth = r - (0.8 + 0.05*sin(32*theta)); hole = 0.25 - r; slab = abs(y) - 0.15; \
                  max(max(teeth, hole), slab)",
        about: "the paper's Fig. 7(a): the 32-tooth gear contour r - (0.8 + 0.05 sin(32 theta)) \
                cut by a bore and two planes",
        paper_seconds_at_512: Some(12.0),
    },
    Example {
        name: "crankshaft",
        coordinates: Coordinates::Cylindrical,
        formula: "web = max(1.5*r - (1.2 + 0.05*sin(3*theta)), abs(y) - 0.12); \
                  shaft = max(r - 0.22, abs(y) - 0.9); \
                  pin = max(sqrt((x - 0.5)^2 + z^2) - 0.12, abs(y - 0.3) - 0.2); \
                  min(min(web, shaft), pin)",
        about: "the paper's Fig. 7(b): a crank web of contour r - (1.2 + 0.05 sin(3 theta)) (scaled \
                by 2/3 into the unit box) on a shaft, with a crank pin (cylinders and planes by \
                min/max)",
        paper_seconds_at_512: Some(14.0),
    },
];

/// The example called `name`, or an error listing them all.
pub fn example(name: &str) -> Result<&'static Example> {
    EXAMPLES.iter().find(|e| e.name == name).ok_or_else(|| {
        let names: Vec<&str> = EXAMPLES.iter().map(|e| e.name).collect();
        Error::InvalidArgument(format!(
            "no example `{name}`; there are {}",
            names.join(", ")
        ))
    })
}
