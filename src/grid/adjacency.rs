//! Voxel adjacency: 6 (shared face), 18 (face or edge), 26 (face, edge or corner).

/// Which neighbours count as adjacent.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Adjacency {
    Six,
    Eighteen,
    TwentySix,
}

crate::named_choices! {
    Adjacency, "the adjacency":
    "6" => Six,
    "18" => Eighteen,
    "26" => TwentySix,
}

impl Adjacency {
    pub fn number(self) -> u32 {
        match self {
            Adjacency::Six => 6,
            Adjacency::Eighteen => 18,
            Adjacency::TwentySix => 26,
        }
    }

    /// Whether offset `d` (each component in -1..=1, not all zero) is a neighbour.
    pub fn includes(self, d: [i64; 3]) -> bool {
        let nonzero = d.iter().filter(|&&v| v != 0).count();
        nonzero > 0
            && match self {
                Adjacency::Six => nonzero == 1,
                Adjacency::Eighteen => nonzero <= 2,
                Adjacency::TwentySix => true,
            }
    }

    /// The neighbour offsets.
    pub fn offsets(self) -> Vec<[i64; 3]> {
        let mut v = Vec::with_capacity(26);
        for x in -1..=1 {
            for y in -1..=1 {
                for z in -1..=1 {
                    if self.includes([x, y, z]) {
                        v.push([x, y, z]);
                    }
                }
            }
        }
        v
    }
}
