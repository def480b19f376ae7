//! Where a vertex can be the nearest point of a mesh: the cone its half-spaces leave (behind
//! every edge and fan diagonal leaving it, `distance_band`), within a radius. On a smooth mesh
//! that cone is thin where the surface is convex or concave and only its apex at a saddle, so
//! bounding it spares most of the ball's columns (igea at 1024: 41% of its (brick, vertex) pairs
//! have no cone beyond the apex).
//!
//! A cone holding no line is the conic hull of its extreme rays, each where two of its planes
//! meet, and lies within the circular cone around their mean direction that reaches the
//! farthest of them. A vertex's planes all pass through it (their margins aside: a point that
//! only the margins admit has another feature nearest, which marks it), so only their
//! directions count.

use super::separating_kernel::{HalfSpace, SECTOR_ANGLE_SLACK, SECTOR_SLACK};
use glam::DVec3;

/// The most extreme rays kept; a cone with more is bounded by the whole ball.
const MOST_RAYS: usize = 32;

/// Planes whose normals' cross product is shorter than this are taken as parallel, and the
/// cone as the whole ball (duplicated edges of a degenerate mesh).
const LEAST_CROSS: f64 = 1e-9;

/// Where the cone of `halves` (through the vertex) lies within radius `r` of it.
#[derive(Debug, PartialEq)]
pub(super) enum ConeReach {
    /// Nowhere beyond the vertex itself.
    Apex,
    /// Within these offsets from the vertex, by axis: lowest and highest.
    Within(DVec3, DVec3),
}

/// Bounds the cone that `halves` leave around their common point within radius `r`.
pub(super) fn cone_reach(halves: &[HalfSpace], r: f64) -> ConeReach {
    let ball = ConeReach::Within(DVec3::splat(-r), DVec3::splat(r));
    // Fewer than three planes leave a line in the cone.
    if halves.len() < 3 {
        return ball;
    }
    let mut rays = [DVec3::ZERO; MOST_RAYS];
    let mut count = 0;
    for (i, a) in halves.iter().enumerate() {
        for b in &halves[i + 1..] {
            let u = a.g.cross(b.g);
            let len2 = u.length_squared();
            if len2 < LEAST_CROSS * LEAST_CROSS {
                return ball;
            }
            // g·u within SECTOR_ANGLE_SLACK |u| of the half-space, without a root for the
            // pairs (most) that no half-space keeps.
            let slack2 = SECTOR_ANGLE_SLACK * SECTOR_ANGLE_SLACK * len2;
            let (mut along, mut against) = (true, true);
            for h in halves {
                let s = h.g.dot(u);
                let small = s * s <= slack2;
                along &= s <= 0.0 || small;
                against &= s >= 0.0 || small;
            }
            if along && against {
                return ball; // the line through both ways lies in the cone
            }
            if !(along || against) {
                continue;
            }
            let u = u / len2.sqrt();
            for (kept, ray) in [(along, u), (against, -u)] {
                if kept {
                    if count == MOST_RAYS {
                        return ball;
                    }
                    rays[count] = ray;
                    count += 1;
                }
            }
        }
    }
    let rays = &rays[..count];
    if rays.is_empty() {
        return ConeReach::Apex;
    }
    let Some(c) = rays.iter().sum::<DVec3>().try_normalize() else {
        return ball;
    };
    let cos_b = rays.iter().map(|u| c.dot(*u)).fold(1.0f64, f64::min);
    if cos_b <= 0.0 {
        return ball;
    }
    let sin_b = (1.0 - cos_b * cos_b).max(0.0).sqrt();
    // The farthest a unit vector within angle b of c goes along a unit direction at cosine
    // `cos_t` from c: all the way where the direction is within b, else cos(t - b).
    let farthest = |cos_t: f64| {
        if cos_t >= cos_b {
            1.0
        } else {
            cos_t * cos_b + (1.0 - cos_t * cos_t).max(0.0).sqrt() * sin_b
        }
    };
    // The apex is in the cone: the bounds reach it at least. Where no ray goes one way along
    // an axis, no point of their hull does either.
    let (ray_lo, ray_hi) = rays.iter().fold((DVec3::ZERO, DVec3::ZERO), |(lo, hi), u| {
        (lo.min(*u), hi.max(*u))
    });
    let circular = |c: DVec3| DVec3::new(farthest(c.x), farthest(c.y), farthest(c.z));
    let hi = circular(c).min(DVec3::ONE).max(DVec3::ZERO)
        * DVec3::select(ray_hi.cmpgt(DVec3::ZERO), DVec3::ONE, DVec3::ZERO);
    let lo = circular(-c).min(DVec3::ONE).max(DVec3::ZERO)
        * DVec3::select(ray_lo.cmplt(DVec3::ZERO), DVec3::ONE, DVec3::ZERO);
    let slack = DVec3::splat(SECTOR_SLACK);
    ConeReach::Within(-lo * r - slack, hi * r + slack)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::SplitMix64;

    fn halves_of(directions: &[DVec3]) -> Vec<HalfSpace> {
        directions
            .iter()
            .map(|d| HalfSpace {
                g: d.normalize(),
                h: 0.0,
            })
            .collect()
    }

    fn random_unit(random: &mut SplitMix64) -> DVec3 {
        loop {
            let v = DVec3::new(
                random.range(-1.0, 1.0),
                random.range(-1.0, 1.0),
                random.range(-1.0, 1.0),
            );
            if (0.01..=1.0).contains(&v.length_squared()) {
                return v.normalize();
            }
        }
    }

    /// Vertices with random neighbours (fans around a random normal, bent up or down at
    /// random: convex, concave and saddle vertices), against directions drawn at random and
    /// kept where they lie in every half-space: each such direction, at any length up to the
    /// radius, lies within the bounds; a cone reported as its apex holds none of them.
    #[test]
    fn the_bounds_hold_every_direction_in_the_cone() {
        let mut random = SplitMix64(7);
        let (mut apexes, mut bounded) = (0, 0);
        for _ in 0..400 {
            let n = random_unit(&mut random);
            let t = n.any_orthonormal_vector();
            let s = n.cross(t);
            let k = 3 + (random.next_u64() % 6) as usize;
            let neighbours: Vec<DVec3> = (0..k)
                .map(|j| {
                    let angle =
                        std::f64::consts::TAU * (j as f64 + random.range(0.0, 0.8)) / k as f64;
                    t * angle.cos() + s * angle.sin() + n * random.range(-0.6, 0.6)
                })
                .collect();
            let halves = halves_of(&neighbours);
            let r = 3.0;
            let reach = cone_reach(&halves, r);
            for _ in 0..4000 {
                let u = random_unit(&mut random);
                if halves.iter().any(|h| h.g.dot(u) > 0.0) {
                    continue;
                }
                let x = u * r * random.range(0.0, 1.0);
                match &reach {
                    ConeReach::Apex => panic!("{u} lies in a cone reported empty: {neighbours:?}"),
                    ConeReach::Within(lo, hi) => assert!(
                        x.cmpge(*lo).all() && x.cmple(*hi).all(),
                        "{x} is outside {lo}..{hi}: {neighbours:?}"
                    ),
                }
            }
            match reach {
                ConeReach::Apex => apexes += 1,
                ConeReach::Within(lo, hi) if (hi - lo).max_element() < 2.0 * r => bounded += 1,
                ConeReach::Within(..) => {}
            }
        }
        // Both outcomes are exercised, and most cones are bounded short of the ball.
        assert!(
            apexes > 40 && bounded > 100,
            "{apexes} apexes, {bounded} bounded"
        );
    }

    #[test]
    fn a_cube_corner_reaches_only_its_octant() {
        // The corner at the origin with edges along +x, +y, +z: its cone is the -x-y-z octant.
        let halves = halves_of(&[DVec3::X, DVec3::Y, DVec3::Z]);
        let ConeReach::Within(lo, hi) = cone_reach(&halves, 2.0) else {
            panic!("a cube corner has a cone");
        };
        assert!(hi.max_element() <= SECTOR_SLACK + 1e-12, "{hi}");
        assert!(
            lo.cmpge(DVec3::splat(-2.0 - SECTOR_SLACK - 1e-12)).all(),
            "{lo}"
        );
        // A plane's worth of directions around a point: a saddle-free flat vertex holds the
        // normal line both ways, so the whole ball.
        let flat = halves_of(&[DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y]);
        assert_eq!(
            cone_reach(&flat, 2.0),
            ConeReach::Within(DVec3::splat(-2.0), DVec3::splat(2.0))
        );
    }
}
