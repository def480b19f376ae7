//! OpenSubdiv's creasing rules (Sdc, `CREASE_UNIFORM`): sharpness of edges and vertices, how
//! it decreases by one per subdivision step, which rule a vertex follows, and the fractional
//! weight that blends a rule into the next one when sharpness runs out.
//!
//! Sharpness is kept in `f32` and the fractional weights are computed in `f32`, as OpenSubdiv
//! does, so that a semi-sharp surface equals OpenSubdiv's to rounding (a sharpness of 7.9 ends
//! with a fraction of 0.9000001, not 0.9).

/// Sharpness from which a crease or corner never softens (`Sdc::Crease::SHARPNESS_INFINITE`).
pub(crate) const INFINITE: f32 = 10.0;

#[inline]
pub(crate) fn is_sharp(s: f32) -> bool {
    s > 0.0
}

#[inline]
pub(crate) fn is_infinite(s: f32) -> bool {
    s >= INFINITE
}

/// Sharpness one subdivision step later.
#[inline]
pub(crate) fn child_sharpness(s: f32) -> f32 {
    if is_infinite(s) {
        s
    } else {
        (s - 1.0).max(0.0)
    }
}

/// How a vertex moves in a subdivision step and where its limit lies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Rule {
    Smooth,
    /// One sharp edge, ending there: moves by the smooth rule.
    Dart,
    /// Exactly two sharp edges: the vertex moves along the crease curve they form.
    Crease,
    /// A sharp vertex, or more than two sharp edges: the vertex stays.
    Corner,
}

/// The rule of a vertex from its own sharpness and that of its edges (boundary edges count as
/// infinitely sharp).
pub(crate) fn vertex_rule(vertex: f32, edges: impl Iterator<Item = f32>) -> Rule {
    if is_sharp(vertex) {
        return Rule::Corner;
    }
    match edges.filter(|&s| is_sharp(s)).count() {
        0 => Rule::Smooth,
        1 => Rule::Dart,
        2 => Rule::Crease,
        _ => Rule::Corner,
    }
}

/// The weight of the parent's rule where a vertex's rule changes in this step: the mean
/// sharpness of what stops being sharp (the vertex and its edges), at most 1
/// (`Sdc::Crease::ComputeFractionalWeightAtVertex`).
pub(crate) fn fractional_weight(vertex: f32, edges: impl Iterator<Item = f32>) -> f32 {
    let mut count = 0u32;
    let mut sum = 0.0f32;
    for s in std::iter::once(vertex).chain(edges) {
        if is_sharp(s) && !is_sharp(child_sharpness(s)) {
            sum += s;
            count += 1;
        }
    }
    if count == 0 {
        0.0
    } else {
        (sum / count as f32).min(1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sharpness_runs_out_one_step_at_a_time() {
        assert_eq!(child_sharpness(5.0), 4.0);
        assert_eq!(child_sharpness(0.5), 0.0);
        assert_eq!(child_sharpness(INFINITE), INFINITE);
        assert_eq!(child_sharpness(12.0), 12.0);
        // 7.9 in f32 keeps its fraction exactly through the steps.
        let mut s = 7.9f32;
        for _ in 0..7 {
            s = child_sharpness(s);
        }
        assert_eq!(s, 7.9f32 - 7.0);
        assert!((s - 0.9).abs() > 0.0 && (s - 0.9).abs() < 1e-6);
    }

    #[test]
    fn rules_follow_the_sharp_edges() {
        assert_eq!(vertex_rule(0.0, [0.0, 0.0, 0.0].into_iter()), Rule::Smooth);
        assert_eq!(vertex_rule(0.0, [2.0, 0.0, 0.0].into_iter()), Rule::Dart);
        assert_eq!(vertex_rule(0.0, [2.0, 0.0, 1.0].into_iter()), Rule::Crease);
        assert_eq!(vertex_rule(0.0, [2.0, 3.0, 1.0].into_iter()), Rule::Corner);
        assert_eq!(vertex_rule(0.5, [0.0, 0.0].into_iter()), Rule::Corner);
    }

    #[test]
    fn the_weight_averages_what_runs_out() {
        // Edges of 0.5 and 0.9 soften this step, one of 3.0 does not.
        let w = fractional_weight(0.0, [0.5f32, 0.9, 3.0, 0.0].into_iter());
        assert_eq!(w, (0.5f32 + 0.9) / 2.0);
        assert_eq!(fractional_weight(0.0, [3.0f32, 4.0].into_iter()), 0.0);
        assert_eq!(fractional_weight(1.0, [1.0f32].into_iter()), 1.0);
    }
}
