//! The fruit map: detections from many frames, in a fixed frame, associated to tracks with
//! stable ids; each track's centre is a running mean that refuses outliers once it has a few
//! observations, and its ripeness the sum of the frames' stage probabilities (normalised:
//! their mean over the frames, each frame's from the coloured fraction it saw).
//!
//! A track restarts from new evidence: [`FruitMap::restart_after`] observations in a row that
//! it refused as outliers, and it is where they say. Its first observations may be biased
//! (the localization still converging, the fruit seen from afar), and once settled it
//! refused every later, better one: in a family-draw harvest by sight (seed 7001, trial 2) a
//! 41 mm fruit's track settled 20 mm off in its first frames and stayed there, the
//! observations 2-5 mm from the truth all refused, and the node aimed at it.
//!
//! Two tracks closer than the larger one's radius are one fruit (two fruit cannot overlap):
//! the one seen less recently goes ([`FruitMap::update`]). The association gate is at least
//! a track's radius, for the same reason.
//!
//! A map also forgets: a track the camera sees through (depth beyond the fruit's back where
//! its centre projects) in [`FruitMap::drop_after`] frames in a row, with no observation in
//! between, is removed ([`FruitMap::forget_seen_through`]). Tracks made from frames taken
//! while the localization was still converging (trial 35 of the harvest by sight: the first
//! two frames placed three fruit 95 mm off, the map kept them, the node aimed at one of
//! them) and fruit that left their plant are gone after a few frames.

/// One fruit of the map.
#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    pub id: u32,
    pub center: [f64; 3],
    pub radius: f64,
    /// Observations merged into the mean.
    pub merged: u32,
    /// Observations refused as outliers.
    pub refused: u32,
    /// Summed stage votes (index 0 = stage 1).
    pub votes: [f64; 6],
    /// Welford's sum of squared distances to the mean [m^2].
    m2: f64,
    pub last_seen_ns: i64,
    /// Frames in a row that saw through where this fruit should be.
    pub seen_through: u32,
    /// Observations refused in a row, with their running mean and Welford sum.
    streak: Streak,
}

/// Running mean of consecutive refused observations.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Streak {
    n: u32,
    center: [f64; 3],
    radius: f64,
    m2: f64,
}

impl Streak {
    fn add(&mut self, o: &Observation) {
        self.n += 1;
        welford(self.n, &mut self.center, &mut self.radius, &mut self.m2, o);
    }
}

/// Adds observation `o` as the `n`th to a running mean of centre and radius and to Welford's
/// sum of squared distances.
fn welford(n: u32, center: &mut [f64; 3], radius: &mut f64, m2: &mut f64, o: &Observation) {
    let n = n as f64;
    let old = *center;
    for a in 0..3 {
        center[a] += (o.center[a] - center[a]) / n;
    }
    *m2 += dist(o.center, old) * dist(o.center, *center);
    *radius += (o.radius - *radius) / n;
}

impl Track {
    /// RMS spread of the merged observations about the mean [m].
    pub fn spread(&self) -> f64 {
        if self.merged < 2 {
            0.0
        } else {
            (self.m2 / (self.merged - 1) as f64).sqrt()
        }
    }
}

/// What one frame says of a track it did not observe.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Look {
    /// Not in view, hidden behind something nearer, or no depth there: no evidence.
    Unseen,
    /// Something where the fruit should be (it may be there, not detected).
    Occupied,
    /// The depth lies beyond the fruit's back: the fruit is not there.
    SeenThrough,
}

/// An observation to merge: centre in the map's frame, radius, stage votes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Observation {
    pub center: [f64; 3],
    pub radius: f64,
    pub votes: [f64; 6],
}

#[derive(Clone, Debug)]
pub struct FruitMap {
    pub tracks: Vec<Track>,
    next_id: u32,
    /// Largest distance between an observation and a track it joins [m].
    pub gate: f64,
    /// Observations before a track refuses outliers.
    pub settle: u32,
    /// An observation farther than max(outlier_sigmas x spread, outlier_floor) is refused.
    pub outlier_sigmas: f64,
    pub outlier_floor: f64,
    /// Frames in a row that see through a track before it is removed.
    pub drop_after: u32,
    /// Refused observations in a row after which a track restarts from them.
    pub restart_after: u32,
}

impl Default for FruitMap {
    fn default() -> Self {
        FruitMap {
            tracks: vec![],
            next_id: 1,
            gate: 0.035,
            settle: 3,
            outlier_sigmas: 3.0,
            outlier_floor: 0.008,
            drop_after: 3,
            restart_after: 3,
        }
    }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

impl FruitMap {
    /// Merges one frame's observations; returns each one's track id. Observations of one
    /// frame never share a track (nearest pairs first).
    pub fn update(&mut self, obs: &[Observation], t_ns: i64) -> Vec<u32> {
        let mut pairs: Vec<(f64, usize, usize)> = vec![];
        for (i, o) in obs.iter().enumerate() {
            for (k, t) in self.tracks.iter().enumerate() {
                let d = dist(o.center, t.center);
                if d <= self.gate.max(t.radius) {
                    pairs.push((d, i, k));
                }
            }
        }
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let mut of_obs: Vec<Option<usize>> = vec![None; obs.len()];
        let mut taken = vec![false; self.tracks.len()];
        for (_, i, k) in pairs {
            if of_obs[i].is_none() && !taken[k] {
                of_obs[i] = Some(k);
                taken[k] = true;
            }
        }
        let mut ids = Vec::with_capacity(obs.len());
        for (o, slot) in obs.iter().zip(of_obs) {
            match slot {
                Some(k) => {
                    let (sigmas, floor, settle) = (self.outlier_sigmas, self.outlier_floor, self.settle);
                    let restart = self.restart_after;
                    let t = &mut self.tracks[k];
                    let d = dist(o.center, t.center);
                    t.last_seen_ns = t_ns;
                    t.seen_through = 0;
                    if t.merged >= settle && d > (sigmas * t.spread()).max(floor) {
                        t.refused += 1;
                        t.streak.add(o);
                        if t.streak.n >= restart {
                            let s = std::mem::take(&mut t.streak);
                            (t.center, t.radius, t.merged, t.m2) = (s.center, s.radius, s.n, s.m2);
                        }
                    } else {
                        t.streak = Streak::default();
                        t.merged += 1;
                        welford(t.merged, &mut t.center, &mut t.radius, &mut t.m2, o);
                        for s in 0..6 {
                            t.votes[s] += o.votes[s];
                        }
                    }
                    ids.push(t.id);
                }
                None => {
                    let id = self.next_id;
                    self.next_id += 1;
                    self.tracks.push(Track {
                        id,
                        center: o.center,
                        radius: o.radius,
                        merged: 1,
                        refused: 0,
                        votes: o.votes,
                        m2: 0.0,
                        last_seen_ns: t_ns,
                        seen_through: 0,
                        streak: Streak::default(),
                    });
                    ids.push(id);
                }
            }
        }
        for (gone, kept) in self.merge_overlapping(t_ns) {
            ids.iter_mut().filter(|id| **id == gone).for_each(|id| *id = kept);
        }
        ids
    }

    /// Removes, of every two tracks closer than the larger radius, the one seen less
    /// recently (then: with fewer observations, then: the newer id); returns (removed id,
    /// kept id) pairs. Only tracks observed at `t_ns` moved, so only pairs with one of them
    /// are checked (the others were apart after the last update).
    fn merge_overlapping(&mut self, t_ns: i64) -> Vec<(u32, u32)> {
        let mut out = vec![];
        loop {
            let mut worst: Option<(f64, usize, usize)> = None;
            for a in 0..self.tracks.len() {
                for b in a + 1..self.tracks.len() {
                    let (ta, tb) = (&self.tracks[a], &self.tracks[b]);
                    if ta.last_seen_ns != t_ns && tb.last_seen_ns != t_ns {
                        continue;
                    }
                    let d = dist(ta.center, tb.center);
                    if d < ta.radius.max(tb.radius) && worst.is_none_or(|w| d < w.0) {
                        worst = Some((d, a, b));
                    }
                }
            }
            let Some((_, a, b)) = worst else { return out };
            let key = |t: &Track| (t.last_seen_ns, t.merged, std::cmp::Reverse(t.id));
            let (keep, drop) = if key(&self.tracks[a]) >= key(&self.tracks[b]) { (a, b) } else { (b, a) };
            out.push((self.tracks[drop].id, self.tracks[keep].id));
            self.tracks.remove(drop);
        }
    }

    /// Negative evidence of one frame: every track not among `observed` (the ids
    /// [`FruitMap::update`] returned for it) that `look` says the frame saw through counts one
    /// more such frame, one it says is occupied starts again from none; a track seen through
    /// in [`FruitMap::drop_after`] frames in a row is removed. Returns the removed ids.
    pub fn forget_seen_through(&mut self, observed: &[u32], look: impl Fn(&Track) -> Look) -> Vec<u32> {
        for t in self.tracks.iter_mut().filter(|t| !observed.contains(&t.id)) {
            match look(t) {
                Look::SeenThrough => t.seen_through += 1,
                Look::Occupied => t.seen_through = 0,
                Look::Unseen => {}
            }
        }
        let limit = self.drop_after;
        let gone: Vec<u32> = self.tracks.iter().filter(|t| t.seen_through >= limit).map(|t| t.id).collect();
        self.tracks.retain(|t| t.seen_through < limit);
        gone
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::tests::Mix;

    fn ob(c: [f64; 3]) -> Observation {
        Observation { center: c, radius: 0.03, votes: [0.0, 0.0, 0.0, 0.0, 0.2, 0.8] }
    }

    /// Three fruit seen in twenty noisy frames (in changing order, one missed now and then):
    /// three tracks, ids stable frame to frame, means within a millimetre of the truth.
    #[test]
    fn merges_with_stable_ids() {
        let truth = [[1.0, 2.0, 1.0], [1.08, 2.0, 1.02], [1.5, 2.1, 0.8]];
        let mut map = FruitMap::default();
        let mut rng = Mix(11);
        let mut first: Option<Vec<u32>> = None;
        for frame in 0..20 {
            let mut seen: Vec<usize> = (0..3).filter(|&i| (frame + i) % 7 != 0).collect();
            if frame % 2 == 1 {
                seen.reverse();
            }
            let obs: Vec<Observation> =
                seen.iter().map(|&i| ob([0, 1, 2].map(|a| truth[i][a] + 0.002 * rng.normal()))).collect();
            let ids = map.update(&obs, frame as i64);
            let by_truth: Vec<(usize, u32)> = seen.iter().copied().zip(ids).collect();
            if let Some(f) = &first {
                for (i, id) in by_truth {
                    assert_eq!(f[i], id, "frame {frame}: fruit {i} changed id");
                }
            } else if seen.len() == 3 {
                let mut f = vec![0; 3];
                for (i, id) in by_truth {
                    f[i] = id;
                }
                first = Some(f);
            }
        }
        assert_eq!(map.tracks.len(), 3);
        for t in &map.tracks {
            let best = truth.iter().map(|c| dist(*c, t.center)).fold(f64::INFINITY, f64::min);
            assert!(best < 0.0015, "{t:?}");
            assert!(t.spread() > 0.001 && t.spread() < 0.006, "{t:?}");
        }
    }

    /// A track seen through in `drop_after` frames in a row goes; an observation, or a frame
    /// that finds the place occupied, starts its count again; frames that do not see the
    /// place change nothing.
    #[test]
    fn forgets_a_fruit_seen_through() {
        let mut map = FruitMap::default();
        let ids = map.update(&[ob([0.0, 0.0, 1.0]), ob([0.2, 0.0, 1.0])], 0);
        let ghost = ids[0];
        let through = |t: &Track| if t.id == ghost { Look::SeenThrough } else { Look::Occupied };
        // Seen through twice, then observed again: it stays.
        assert!(map.forget_seen_through(&[], through).is_empty());
        assert!(map.forget_seen_through(&[], through).is_empty());
        let ids = map.update(&[ob([0.0, 0.0, 1.0])], 3);
        assert_eq!(ids, vec![ghost]);
        assert!(map.forget_seen_through(&ids, through).is_empty());
        // Seen through twice, occupied once, out of view, seen through twice: it stays.
        for look in
            [Look::SeenThrough, Look::SeenThrough, Look::Occupied, Look::Unseen, Look::SeenThrough, Look::SeenThrough]
        {
            assert!(map.forget_seen_through(&[], |t| if t.id == ghost { look } else { Look::Occupied }).is_empty());
        }
        assert_eq!(map.tracks.len(), 2);
        // A third frame in a row: gone, the other fruit kept, ids not reused.
        assert_eq!(map.forget_seen_through(&[], through), vec![ghost]);
        assert_eq!(map.tracks.len(), 1);
        assert_ne!(map.tracks[0].id, ghost);
        assert_eq!(map.update(&[ob([0.0, 0.0, 1.0])], 9), vec![3]);
    }

    /// Once settled, a wild observation inside the gate is refused and does not move the mean.
    #[test]
    fn refuses_outliers() {
        let mut map = FruitMap::default();
        for k in 0..5 {
            map.update(&[ob([0.0, 0.0, 1.0 + 0.001 * k as f64])], k);
        }
        let before = map.tracks[0].center;
        let ids = map.update(&[ob([0.03, 0.0, 1.0])], 9);
        assert_eq!(ids, vec![map.tracks[0].id]);
        assert_eq!(map.tracks[0].center, before);
        assert_eq!((map.tracks[0].merged, map.tracks[0].refused), (5, 1));
        // Beyond the gate it is a new fruit.
        let ids = map.update(&[ob([0.1, 0.0, 1.0])], 10);
        assert_eq!(ids, vec![2]);
    }

    fn big(c: [f64; 3]) -> Observation {
        Observation { radius: 0.042, ..ob(c) }
    }

    /// A settled track that refuses `restart_after` observations in a row is where they
    /// say (its id kept); one refused observation between merged ones moves nothing.
    #[test]
    fn restarts_from_consistent_refused_observations() {
        let mut map = FruitMap::default();
        for k in 0..5 {
            map.update(&[ob([0.0, 0.0, 1.0 + 0.001 * k as f64])], k);
        }
        let id = map.tracks[0].id;
        let settled = map.tracks[0].center;
        // One wild observation, then agreeing ones: the streak is broken, nothing moves.
        map.update(&[ob([0.02, 0.0, 1.0])], 5);
        map.update(&[ob([0.0, 0.0, 1.002])], 6);
        assert!(dist(map.tracks[0].center, settled) < 0.001);
        // Three in a row 20 mm away (the first frames were biased): the track moves there.
        for k in 0..3 {
            assert!(map.tracks[0].center[0] < 0.01, "moved before the streak was complete");
            assert_eq!(map.update(&[ob([0.02, 0.001 * k as f64, 1.0])], 7 + k), vec![id]);
        }
        let t = &map.tracks[0];
        assert!(dist(t.center, [0.02, 0.001, 1.0]) < 1e-9, "{t:?}");
        assert_eq!((t.merged, t.refused, map.tracks.len()), (3, 4, 1));
        // And it goes on from there as any track.
        map.update(&[ob([0.021, 0.001, 1.0])], 10);
        assert_eq!(map.tracks[0].merged, 4);
    }

    /// A large fruit seen first off by more than the gate gets a second track; once the
    /// second comes closer to the first than the fruit's radius they are one, the one seen
    /// last kept, and the frame's observation names it. Touching fruit stay two.
    #[test]
    fn overlapping_tracks_are_one_fruit() {
        let mut map = FruitMap::default();
        let a = map.update(&[big([0.0, 0.0, 1.0])], 0)[0];
        let b = map.update(&[big([0.045, 0.0, 1.0])], 1)[0];
        assert_ne!(a, b);
        assert_eq!(map.tracks.len(), 2);
        // Nearer b (15 mm) than a (30 mm): joins b, whose mean (37.5 mm from a) now lies
        // within a's radius.
        assert_eq!(map.update(&[big([0.03, 0.0, 1.0])], 2), vec![b]);
        assert_eq!(map.tracks.len(), 1);
        assert_eq!(map.tracks[0].id, b);
        // The gate is at least the radius: 40 mm off still joins the 42 mm fruit.
        assert_eq!(map.update(&[big([0.0775, 0.0, 1.0])], 3), vec![b]);
        // Two 30 mm fruit touching (centres 60 mm apart), seen in many frames, stay two.
        let mut two = FruitMap::default();
        for k in 0..10 {
            let e = 0.003 * (k % 3) as f64;
            two.update(&[ob([0.0, e, 1.0]), ob([0.06, -e, 1.0])], k);
        }
        assert_eq!(two.tracks.len(), 2);
    }
}
