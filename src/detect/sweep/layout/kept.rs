//! A layout kept from last step and updated in place
//! ([`Layout::keep`]): below rayon's grain, where a layout made anew would
//! cost more than the candidates its bands save on the course scenes.

use super::{finish_band, push_next_guests, set_starts, sort_movers, Group, Layout};
use crate::detect::sweep::bands::Bands;
use crate::detect::sweep::hull::{lo, Packed};
use crate::detect::sweep::order::{Boxes, NO_KEY};

impl Layout {
    /// Lays out the first `n` boxes of `slots` again in place, when they
    /// arrive in the order of last step's layout in the same `bands` (their
    /// hulls made anew); returns the boxes with a key (which come first),
    /// or `None`, changing nothing, when they do not.
    ///
    /// Each band's boxes that stayed in it are closed up at its front in
    /// one pass, and the ones that left are held aside; the bands' runs
    /// then move to their new starts (a copy of whole runs, in the order
    /// that overwrites nothing unmoved); each band's stayers are finished
    /// by insertion and its newcomers inserted; and the guests are listed
    /// band by band. On one thread.
    pub(crate) fn keep(&mut self, slots: &mut Boxes, n: usize, bands: &Bands) -> Option<usize> {
        let count = bands.count;
        if self.kept != Some(*bands)
            || self.starts.len() != count + 2
            || self.starts[count + 1] != n
            || slots.len() != n
        {
            return None;
        }
        if self.groups.is_empty() {
            self.groups.push(Group::default());
        }
        let Group {
            guests,
            guest_starts,
            movers,
            order,
            spare,
        } = &mut self.groups[0];
        let (keys, hulls, ids) = (
            &mut slots.keys[..n],
            &mut slots.hulls[..n],
            &mut slots.ids[..n],
        );
        // The boxes that left their band aside; each band's stayers closed
        // up at its front, a run at a time.
        std::mem::swap(&mut self.starts, &mut self.old_starts);
        let (old, edges) = (&self.old_starts, &self.edges);
        movers.clear();
        self.stayed.clear();
        for b in 0..=count {
            let band = old[b]..old[b + 1];
            self.gaps.clear();
            for k in band.clone() {
                let key = keys[k];
                let stays = if b == count {
                    key == NO_KEY
                } else {
                    let v = lo(&hulls[k], bands.across);
                    key != NO_KEY && edges[b] <= v && v < edges[b + 1]
                };
                if !stays {
                    let home = if key == NO_KEY {
                        count
                    } else {
                        bands.of(lo(&hulls[k], bands.across))
                    };
                    movers.push(key, hulls[k], ids[k], home as u32);
                    self.gaps.push(k);
                }
            }
            let mut w = band.start;
            let mut r = band.start;
            for &gap in self.gaps.iter().chain(std::iter::once(&band.end)) {
                if w != r {
                    keys.copy_within(r..gap, w);
                    hulls.copy_within(r..gap, w);
                    ids.copy_within(r..gap, w);
                }
                w += gap - r;
                r = gap + 1;
            }
            self.stayed.push(w - band.start);
        }
        // The new starts: each band's stayers and newcomers.
        self.counts.clear();
        self.counts.extend(self.stayed.iter().map(|&s| s as u32));
        for &b in &movers.ends {
            self.counts[b as usize] += 1;
        }
        set_starts(&self.counts, &mut self.starts, n);
        // The runs of stayers to their new starts: those moving up from
        // the last band down, then those moving down from the first up,
        // so that no run lands on one not yet moved.
        let new = &self.starts;
        let shift = |b: usize, keys: &mut [f32], hulls: &mut [Packed], ids: &mut [u32]| {
            let run = old[b]..old[b] + self.stayed[b];
            keys.copy_within(run.clone(), new[b]);
            hulls.copy_within(run.clone(), new[b]);
            ids.copy_within(run, new[b]);
        };
        for b in (0..=count).rev().filter(|&b| new[b] > old[b]) {
            shift(b, keys, hulls, ids);
        }
        for b in (0..=count).filter(|&b| new[b] < old[b]) {
            shift(b, keys, hulls, ids);
        }
        // Each band sorted, its newcomers inserted; then its guests.
        if movers.len() > 0 {
            sort_movers(movers, order, spare);
        }
        guests.clear();
        guest_starts.clear();
        guest_starts.push(0);
        let mut mover_at = 0;
        for b in 0..=count {
            let out = new[b]..new[b + 1];
            let stayed = out.start..out.start + self.stayed[b];
            let moved = mover_at..mover_at + (out.len() - stayed.len());
            mover_at = moved.end;
            if b == count {
                // The boxes without a key: in any order.
                for (at, m) in (stayed.end..).zip(moved) {
                    keys[at] = movers.keys[m];
                    hulls[at] = movers.hulls[m];
                    ids[at] = movers.ids[m];
                }
                break;
            }
            let band_arrays = (
                &mut keys[out.clone()],
                &mut hulls[out.clone()],
                &mut ids[out.clone()],
            );
            finish_band(band_arrays, stayed.len(), movers, moved, order, spare);
            let own = guest_starts[b] as usize..guests.len();
            guest_starts.push(guests.len() as u32);
            if b + 1 < count {
                let homes = (&keys[out.clone()], &hulls[out.clone()], &ids[out]);
                push_next_guests(guests, own, homes, b, bands, spare);
            }
        }
        self.guest_at.clear();
        for b in 0..count {
            self.guest_at
                .push((0, guest_starts[b]..guest_starts[b + 1]));
        }
        Some(self.starts[count])
    }
}
