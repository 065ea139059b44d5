//! The epochs of a partitioned level (see [`super::partition`]) without a barrier after each:
//! a region runs its next epoch as soon as no earlier epoch can be the level's last, so a core
//! that finishes early goes on (often with the region it has in cache) instead of waiting for
//! the slowest region of the epoch. Every region still runs exactly the epochs 0 to E of the
//! barrier loop, E the first epoch after which the level may stop, so the result is the
//! barrier loop's, bit for bit, on any thread count.
//!
//! An epoch e cannot be the last once it is known that its ceiling is finite, that some region
//! stopped at that ceiling in e, and that the faces after e exceed the level's stop: the faces
//! of the regions that finished e, plus for each region that has not the least it can still
//! end at (`Epochs::lowest`), already exceed it.

use crate::options::Cancel;
use std::sync::{Condvar, Mutex, MutexGuard};

/// The first epoch's cost ceiling: far below the cheapest edge.
pub(super) const FIRST_CEILING: f32 = 1e-30;

/// A region as the epochs drive it.
pub(super) trait Epochs: Send {
    /// Its faces now, the crossing faces it holds left out (they are counted once).
    fn counted(&self) -> usize;
    /// The least [`Epochs::counted`] any later epoch can leave.
    fn lowest(&self) -> usize;
    /// Runs to the cost ceiling `limit` (an f32's bits); true when it stopped at the ceiling.
    fn epoch(&mut self, limit: u32) -> bool;
}

/// Where a level stops: after the first epoch that leaves at most `stop_at` faces (the regions'
/// [`Epochs::counted`] plus `cut_faces`), in which no region stopped at its ceiling, or whose
/// ceiling (`FIRST_CEILING · stepᵉ`) is infinite; or once `cancel` is set.
#[derive(Clone, Copy)]
pub(super) struct Stop<'a> {
    pub step: f32,
    pub stop_at: usize,
    pub cut_faces: usize,
    pub cancel: &'a Cancel,
}

/// The barrier loop's epochs on `regions`, on up to `threads` threads (the caller's among
/// them: `progress` is called there, with the faces after each epoch, in order). Threads of
/// their own, not rayon's: a worker with nothing to run waits for the others, which a rayon
/// task must not do (the task it waits for may be queued behind it); for the same reason a
/// region's refills stay on its thread (`State::one_thread`).
pub(super) fn run<R: Epochs>(
    regions: &mut [R],
    stop: Stop,
    threads: usize,
    progress: &mut dyn FnMut(usize),
) {
    let n = regions.len();
    if n == 0 {
        return;
    }
    let low = regions.iter().map(Epochs::lowest).collect();
    let slots: Vec<Option<&mut R>> = regions.iter_mut().map(Some).collect();
    let shared = Shared {
        sched: Mutex::new(Sched {
            slots,
            next: vec![0; n],
            low,
            epochs: Vec::new(),
            settled: 0,
            last: None,
            reported: 0,
            aborted: false,
        }),
        wake: Condvar::new(),
        stop,
    };
    let threads = threads.clamp(1, n);
    std::thread::scope(|scope| {
        for _ in 1..threads {
            scope.spawn(|| shared.work(None));
        }
        shared.work(Some(progress));
    });
}

/// One epoch's tally.
struct Epoch {
    ceiling: f32,
    /// Regions that finished it.
    done: usize,
    /// Their faces after it.
    counted: usize,
    /// Whether any of them stopped at the ceiling.
    more: bool,
}

struct Sched<'r, R> {
    /// A region out of its slot is running.
    slots: Vec<Option<&'r mut R>>,
    /// Per region, the next epoch it runs.
    next: Vec<usize>,
    /// Per region, [`Epochs::lowest`] after its last epoch.
    low: Vec<usize>,
    epochs: Vec<Epoch>,
    /// Every epoch before this one is known not to be the last.
    settled: usize,
    /// The last epoch, once known.
    last: Option<usize>,
    /// Epochs whose faces went to the caller's `progress`.
    reported: usize,
    /// A worker panicked: the others stop (the panic goes on to the caller).
    aborted: bool,
}

struct Shared<'r, 'c, R> {
    sched: Mutex<Sched<'r, R>>,
    wake: Condvar,
    stop: Stop<'c>,
}

impl<R> Sched<'_, R> {
    fn epoch(&mut self, e: usize, step: f32) -> &mut Epoch {
        while self.epochs.len() <= e {
            let ceiling = self
                .epochs
                .last()
                .map_or(FIRST_CEILING, |p| p.ceiling * step);
            self.epochs.push(Epoch {
                ceiling,
                done: 0,
                counted: 0,
                more: false,
            });
        }
        &mut self.epochs[e]
    }

    /// Moves `settled` over every epoch now known not to be the last, or sets `last`.
    fn settle(&mut self, stop: &Stop) {
        let n = self.next.len();
        while self.last.is_none() {
            let e = self.settled;
            let (ceiling, done, counted, more) = {
                let ep = self.epoch(e, stop.step);
                (ep.ceiling, ep.done, ep.counted, ep.more)
            };
            let pending: usize = (0..n)
                .filter(|&r| self.next[r] <= e)
                .map(|r| self.low[r])
                .sum();
            let faces = counted + pending + stop.cut_faces;
            let goes_on = ceiling.is_finite() && more && faces > stop.stop_at;
            if done == n && (!goes_on || stop.cancel.is_cancelled()) {
                self.last = Some(e);
            } else if goes_on && !stop.cancel.is_cancelled() {
                self.settled += 1;
            } else {
                return;
            }
        }
    }

    /// A region that may run its next epoch now: `prefer` if it may, else the one furthest
    /// behind (the lowest index among equals).
    fn pick(&self, prefer: Option<usize>) -> Option<usize> {
        let may = |r: usize| {
            self.slots[r].is_some()
                && self.next[r] <= self.settled
                && self.last.is_none_or(|l| self.next[r] <= l)
        };
        prefer.filter(|&r| may(r)).or_else(|| {
            (0..self.next.len())
                .filter(|&r| may(r))
                .min_by_key(|&r| self.next[r])
        })
    }

    fn finished(&self) -> bool {
        self.aborted
            || self.last.is_some_and(|l| {
                self.slots.iter().all(Option::is_some) && self.next.iter().all(|&e| e > l)
            })
    }
}

impl<'r, R: Epochs> Shared<'r, '_, R> {
    fn lock(&self) -> MutexGuard<'_, Sched<'r, R>> {
        // A worker that panicked set `aborted` first; the data is not used after that.
        self.sched.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Runs regions' epochs until the level's last epoch is done; `progress` on the caller's
    /// thread only.
    fn work(&self, mut progress: Option<&mut dyn FnMut(usize)>) {
        let guard = AbortOnPanic(self);
        let mut prefer = None;
        let mut s = self.lock();
        loop {
            // The faces after each epoch every region has finished, in order.
            while let Some(p) = progress.as_mut()
                && s.reported < s.epochs.len()
                && s.epochs[s.reported].done == s.next.len()
                && s.last.is_none_or(|l| s.reported <= l)
            {
                p(s.epochs[s.reported].counted + self.stop.cut_faces);
                s.reported += 1;
            }
            if s.finished() {
                break;
            }
            let Some(r) = s.pick(prefer) else {
                s = self.wake.wait(s).unwrap_or_else(|e| e.into_inner());
                continue;
            };
            let e = s.next[r];
            let limit = s.epoch(e, self.stop.step).ceiling.to_bits();
            let region = s.slots[r]
                .take()
                .expect("a region runs on one thread at a time");
            drop(s);
            let more = region.epoch(limit);
            let (counted, lowest) = (region.counted(), region.lowest());
            s = self.lock();
            s.slots[r] = Some(region);
            s.next[r] = e + 1;
            s.low[r] = lowest;
            let ep = s.epoch(e, self.stop.step);
            ep.done += 1;
            ep.counted += counted;
            ep.more |= more;
            s.settle(&self.stop);
            prefer = Some(r);
            self.wake.notify_all();
        }
        drop(s);
        std::mem::forget(guard);
        self.wake.notify_all();
    }
}

/// Wakes the other workers to stop when one panics, so that none waits for it forever.
struct AbortOnPanic<'a, 'r, 'c, R: Epochs>(&'a Shared<'r, 'c, R>);

impl<R: Epochs> Drop for AbortOnPanic<'_, '_, '_, R> {
    fn drop(&mut self) {
        self.0.lock().aborted = true;
        self.0.wake.notify_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A region whose collapses have the costs `costs` (rising), each removing `per` faces,
    /// down to `floor`: the epochs it ran are logged.
    struct Fake {
        costs: Vec<f32>,
        next: usize,
        faces: usize,
        floor: usize,
        per: usize,
        own_cut: usize,
        ran: Vec<u32>,
    }

    impl Epochs for Fake {
        fn counted(&self) -> usize {
            self.faces - self.own_cut
        }
        fn lowest(&self) -> usize {
            self.faces
                .min(self.floor.saturating_sub(1))
                .saturating_sub(self.own_cut)
        }
        fn epoch(&mut self, limit: u32) -> bool {
            self.ran.push(limit);
            while self.faces > self.floor {
                let Some(&c) = self.costs.get(self.next) else {
                    return false;
                };
                if c.to_bits() > limit {
                    return true;
                }
                self.next += 1;
                self.faces -= self.per.min(self.faces);
            }
            false
        }
    }

    /// Regions of varied sizes and costs, from a seed.
    fn regions(seed: u64, n: usize) -> Vec<Fake> {
        let mut x = seed;
        let mut rand = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        (0..n)
            .map(|_| {
                let faces = 200 + (rand() % 800) as usize;
                let mut costs: Vec<f32> = (0..faces / 2)
                    .map(|_| 1e-12 * (1 + rand() % 1_000_000) as f32)
                    .collect();
                costs.sort_by(f32::total_cmp);
                if rand() % 2 == 0 {
                    // Only an infinite ceiling takes it.
                    costs.push(f32::MAX);
                }
                Fake {
                    costs,
                    next: 0,
                    faces,
                    floor: faces / 4 + (rand() % 50) as usize,
                    per: 1 + (rand() % 2) as usize,
                    own_cut: (rand() % 20) as usize,
                    ran: Vec::new(),
                }
            })
            .collect()
    }

    /// The loop with a barrier after each epoch, which [`run`] must match.
    fn barrier(regions: &mut [Fake], stop: Stop, progress: &mut Vec<usize>) {
        let mut ceiling = FIRST_CEILING;
        loop {
            let more: Vec<bool> = regions
                .iter_mut()
                .map(|r| r.epoch(ceiling.to_bits()))
                .collect();
            let faces = regions.iter().map(Epochs::counted).sum::<usize>() + stop.cut_faces;
            progress.push(faces);
            if faces <= stop.stop_at
                || !more.contains(&true)
                || !ceiling.is_finite()
                || stop.cancel.is_cancelled()
            {
                break;
            }
            ceiling *= stop.step;
        }
    }

    /// Every region runs the barrier loop's epochs, no more and no fewer, and the progress is
    /// the same, on 1 to 8 threads: stops at the face count (at several depths), where every
    /// region is at its floor, and at an infinite ceiling.
    #[test]
    fn epochs_without_barriers_run_what_the_barrier_loop_runs() {
        let cancel = Cancel::default();
        let mut stops_seen = std::collections::BTreeSet::new();
        let mut infinite = false;
        for seed in 1..=12u64 {
            for n in [1, 3, 8, 13] {
                let total: usize = regions(seed, n).iter().map(|r| r.faces).sum();
                for (share, step) in [
                    (0.9, 2.0),
                    (0.6, 2.0),
                    (0.3, 4.0),
                    (0.0, 64.0),
                    (0.7, 1e6),
                    (0.0, 1e6),
                ] {
                    let stop = Stop {
                        step,
                        stop_at: (total as f64 * share) as usize,
                        cut_faces: 5,
                        cancel: &cancel,
                    };
                    let mut want = regions(seed, n);
                    let mut want_progress = Vec::new();
                    barrier(&mut want, stop, &mut want_progress);
                    stops_seen.insert(want_progress.len());
                    infinite |= want
                        .iter()
                        .any(|r| r.ran.last() == Some(&f32::INFINITY.to_bits()));
                    for threads in [1, 2, 3, 8] {
                        let mut got = regions(seed, n);
                        let mut got_progress = Vec::new();
                        run(&mut got, stop, threads, &mut |f| got_progress.push(f));
                        for (g, w) in got.iter().zip(&want) {
                            assert_eq!(g.ran, w.ran, "seed {seed}, {n} regions, {threads} threads");
                            assert_eq!(g.faces, w.faces);
                        }
                        assert_eq!(got_progress, want_progress);
                    }
                }
            }
        }
        // The cases stop after few and after many epochs.
        assert!(stops_seen.len() > 10, "{stops_seen:?}");
        assert!(infinite, "no case reached the infinite ceiling");
    }

    /// A cancelled level stops after its current epoch, as the barrier loop does.
    #[test]
    fn a_cancelled_level_stops_after_one_epoch() {
        let cancel = Cancel::default();
        cancel.cancel();
        let stop = Stop {
            step: 2.0,
            stop_at: 0,
            cut_faces: 0,
            cancel: &cancel,
        };
        let mut r = regions(3, 8);
        run(&mut r, stop, 2, &mut |_| {});
        assert!(r.iter().all(|r| r.ran.len() == 1));
    }
}
