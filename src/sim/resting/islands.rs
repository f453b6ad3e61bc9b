//! Islands: groups of balls joined by contacts (union–find with path halving). Pure; used by
//! sleep, which puts whole islands to sleep, and by the soak's energy allowance, which lifts a
//! whole island by the overlaps inside it.

/// Which island each of a fixed set of balls is in, as contacts join them.
#[derive(Clone, Debug)]
pub struct Islands {
    parent: Vec<u32>,
}

impl Islands {
    /// `count` balls, each its own island.
    pub fn new(count: usize) -> Self {
        Self {
            parent: (0..count as u32).collect(),
        }
    }

    /// The island of `ball`, named by its lowest-numbered member found so far.
    pub fn root(&mut self, mut ball: u32) -> u32 {
        let parent = &mut self.parent;
        while parent[ball as usize] != ball {
            let grandparent = parent[parent[ball as usize] as usize];
            parent[ball as usize] = grandparent;
            ball = grandparent;
        }
        ball
    }

    /// Puts `a` and `b` in one island.
    pub fn join(&mut self, a: u32, b: u32) {
        let (root_a, root_b) = (self.root(a), self.root(b));
        if root_a != root_b {
            let (low, high) = (root_a.min(root_b), root_a.max(root_b));
            self.parent[high as usize] = low;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joined_balls_share_the_lowest_root_and_others_keep_their_own() {
        let mut islands = Islands::new(6);
        islands.join(4, 2);
        islands.join(2, 5);
        islands.join(1, 3);
        let roots: Vec<u32> = (0..6).map(|ball| islands.root(ball)).collect();
        assert_eq!(roots, [0, 1, 2, 1, 2, 2]);
    }
}
