//! The allowed-collision matrix: which link pairs collision checking skips, and why.

use trm_kinematics::{DisableReason, DisabledCollisionSpec, RobotModel};

/// A symmetric link × link table: `None` = the pair is checked, `Some(reason)` = skipped.
/// A link is never checked against itself.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AllowedCollisionMatrix {
    links: usize,
    entries: Vec<Option<DisableReason>>,
}

impl AllowedCollisionMatrix {
    /// A matrix over `links` links in which every pair is checked.
    pub fn all_checked(links: usize) -> Self {
        AllowedCollisionMatrix {
            links,
            entries: vec![None; links * links],
        }
    }

    /// Every pair checked except adjacent links: a link and its nearest ancestor that has
    /// geometry (links without geometry are looked through, as for fixed frames).
    pub fn adjacent(model: &RobotModel, has_geometry: &[bool]) -> Self {
        let tree = model.tree();
        let mut acm = Self::all_checked(tree.links.len());
        for (i, _) in tree
            .links
            .iter()
            .enumerate()
            .filter(|(i, _)| has_geometry[*i])
        {
            let mut up = tree.links[i].parent;
            while let Some(p) = up {
                if has_geometry[p] {
                    acm.disable(i, p, DisableReason::Adjacent);
                    break;
                }
                up = tree.links[p].parent;
            }
        }
        acm
    }

    /// Adjacency, then the model description's `disabled_collisions`, then its
    /// `enabled_collisions` (which win over both).
    pub fn from_model(model: &RobotModel, has_geometry: &[bool]) -> Self {
        let mut acm = Self::adjacent(model, has_geometry);
        for d in model.disabled_collisions() {
            acm.disable(d.links[0], d.links[1], d.reason);
        }
        acm.apply_enabled(model);
        acm
    }

    /// Re-enables the pairs the model description forces to be checked.
    pub fn apply_enabled(&mut self, model: &RobotModel) {
        for [a, b] in model.enabled_collisions() {
            self.enable(*a, *b);
        }
    }

    /// Number of links.
    pub fn num_links(&self) -> usize {
        self.links
    }

    /// Skips the pair `(a, b)`; a reason already recorded is kept unless it is weaker
    /// (adjacent beats default beats always/never beats user).
    pub fn disable(&mut self, a: usize, b: usize, reason: DisableReason) {
        if a == b {
            return;
        }
        let keep = self.entries[a * self.links + b].map_or(reason, |r| r.min(reason));
        self.entries[a * self.links + b] = Some(keep);
        self.entries[b * self.links + a] = Some(keep);
    }

    /// Checks the pair `(a, b)` again, whatever excluded it.
    pub fn enable(&mut self, a: usize, b: usize) {
        if a != b {
            self.entries[a * self.links + b] = None;
            self.entries[b * self.links + a] = None;
        }
    }

    /// Why the pair is skipped, or `None` if it is checked. A link with itself is skipped as
    /// adjacent.
    pub fn reason(&self, a: usize, b: usize) -> Option<DisableReason> {
        if a == b {
            Some(DisableReason::Adjacent)
        } else {
            self.entries[a * self.links + b]
        }
    }

    /// Whether collisions between links `a` and `b` are checked.
    pub fn is_checked(&self, a: usize, b: usize) -> bool {
        self.reason(a, b).is_none()
    }

    /// Every skipped pair `([a, b], reason)` with `a < b`, in index order.
    pub fn disabled_pairs(&self) -> impl Iterator<Item = ([usize; 2], DisableReason)> + '_ {
        (0..self.links).flat_map(move |a| {
            (a + 1..self.links)
                .filter_map(move |b| self.entries[a * self.links + b].map(|r| ([a, b], r)))
        })
    }

    /// The skipped pairs whose reason `keep` accepts, by link name, as a model description's
    /// `disabled_collisions` entries (adjacent pairs need no entry: pass
    /// `|r| r != DisableReason::Adjacent`). Write them with
    /// [`DisabledCollisionSpec::list_to_ron`].
    pub fn to_spec(
        &self,
        model: &RobotModel,
        keep: impl Fn(DisableReason) -> bool,
    ) -> Vec<DisabledCollisionSpec> {
        let links = &model.tree().links;
        self.disabled_pairs()
            .filter(|&(_, r)| keep(r))
            .map(|([a, b], reason)| DisabledCollisionSpec {
                a: links[a].name.clone(),
                b: links[b].name.clone(),
                reason,
            })
            .collect()
    }
}
