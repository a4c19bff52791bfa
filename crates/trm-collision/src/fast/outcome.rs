use super::lanes::{F, Flags};
use super::world::limits;
use super::{FAST_LANES, LaneMask};

/// What a block's check found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Verdict {
    /// Lanes certainly colliding. The check stops at the first it finds, so this holds at
    /// least one lane when any lane collides, not necessarily all of them.
    pub colliding: LaneMask,
    /// Lanes neither certainly colliding nor certainly free (a pair within the margin of
    /// contact): check them exactly. Meaningful only when `colliding` is 0.
    pub uncertain: LaneMask,
}

/// What a block's count found ([`FastModel::count`](crate::fast::FastModel::count)): per lane, the link pairs and the (link,
/// world object) pairs certainly colliding, and the lanes with pairs left uncertain (the
/// suspects), whose counts are complete only once those are checked exactly.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Tally {
    /// Link pairs certainly colliding, per lane.
    pub self_pairs: [u32; FAST_LANES],
    /// (link, world object) pairs certainly colliding, per lane.
    pub world_pairs: [u32; FAST_LANES],
    /// Lanes with a pair neither certainly colliding nor certainly free.
    pub uncertain: LaneMask,
    pub(super) counting_self: bool,
}

/// Lane flags of a group of pairs: certainly colliding, or within the margin of contact (or
/// NaN).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Contact {
    pub(super) hit: Flags,
    pub(super) close: Flags,
}

impl Contact {
    /// Adds a pair at squared distance `d2` whose radii sum to `r`.
    #[inline(always)]
    pub(super) fn add(&mut self, d2: F, r: f32, m: f32) {
        self.add_within(d2, limits(r, m));
    }

    /// Adds a pair at squared distance `d2` whose [`limits`] are `[inner2, outer2]`.
    #[inline(always)]
    pub(super) fn add_within(&mut self, d2: F, [inner2, outer2]: [f32; 2]) {
        self.hit = self.hit | d2.below(inner2);
        self.close = self.close | d2.within(outer2);
    }

    /// Flags certainly uncertain in every lane (a shape seen through its bounding sphere).
    #[inline(always)]
    pub(super) fn add_uncertain(&mut self, d2: F, reach: f32) {
        self.close = self.close | d2.within(reach * reach);
    }
}

/// What the screen's walk makes of each group of pairs' contacts: a [`Verdict`] (stops at the
/// first certain collision) or a [`Tally`] (counts every colliding pair).
pub(super) trait Outcome {
    /// Whether the walk ends at the first certain collision (then the pair the last walk
    /// ended at is tested first).
    const STOPS_AT_FIRST: bool;
    /// Adds the contacts of a group of pairs in the lanes of `lanes`: `hit`, the lanes certainly
    /// colliding (for bodies screened through enclosing spheres, those touching a sphere inside
    /// them), and `close`, those within the margin of contact. `None` when the walk may stop,
    /// else the lanes the group left uncertain.
    fn add(&mut self, lanes: LaneMask, hit: LaneMask, close: LaneMask) -> Option<LaneMask>;
    /// The world's objects are done; link pairs follow.
    fn enter_self(&mut self) {}
    /// Whether the outcome is known without the uncertain lanes.
    fn settled(&self) -> bool;
    /// The lanes left uncertain.
    fn uncertain(&mut self) -> &mut LaneMask;
}

impl Outcome for Verdict {
    const STOPS_AT_FIRST: bool = true;
    #[inline(always)]
    fn add(&mut self, lanes: LaneMask, hit: LaneMask, close: LaneMask) -> Option<LaneMask> {
        let hit = lanes & hit;
        if hit != 0 {
            self.colliding |= hit;
            return None;
        }
        let uncertain = lanes & close;
        self.uncertain |= uncertain;
        Some(uncertain)
    }
    fn settled(&self) -> bool {
        self.colliding != 0
    }
    fn uncertain(&mut self) -> &mut LaneMask {
        &mut self.uncertain
    }
}

impl Outcome for Tally {
    const STOPS_AT_FIRST: bool = false;
    #[inline(always)]
    fn add(&mut self, lanes: LaneMask, hit: LaneMask, close: LaneMask) -> Option<LaneMask> {
        let hit = lanes & hit;
        let counts = if self.counting_self {
            &mut self.self_pairs
        } else {
            &mut self.world_pairs
        };
        let mut bits = hit;
        while bits != 0 {
            counts[bits.trailing_zeros() as usize] += 1;
            bits &= bits - 1;
        }
        let uncertain = lanes & close & !hit;
        self.uncertain |= uncertain;
        Some(uncertain)
    }
    fn enter_self(&mut self) {
        self.counting_self = true;
    }
    fn settled(&self) -> bool {
        false
    }
    fn uncertain(&mut self) -> &mut LaneMask {
        &mut self.uncertain
    }
}
