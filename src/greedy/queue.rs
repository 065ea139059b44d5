//! The priority queue of edges: a bucket queue on the keys' top bits in front of a binary heap,
//! and the key of a priority.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// The queue of (key, a, b, stamp) entries: a bucket queue on the key's top bits (f32
/// exponent and three mantissa bits, so a bucket spans 6-12.5% of cost) in front of a binary heap
/// that orders the one bucket being taken. An entry is appended to its bucket, moved once into
/// the heap when its bucket comes up, and popped; an edge re-keyed below the bucket being taken
/// (a collapse can make a neighbouring edge cheaper than the edge just taken) goes straight into
/// the heap. Ties come out in (a, b) order, so the order never depends on anything but the
/// entries. When a bucket comes up its stale entries (most are: an edge is re-keyed each time a
/// collapse touches it; 4.2M of 5.3M pops on the 1M scan at 10%) are dropped in one linear
/// pass instead of each costing a heap pop. Measured on the 1M scan at 1%: the radix heap this
/// replaced spent 1.9 G of 13.1 G instructions moving entries between its 33 buckets; std's
/// BinaryHeap over every entry had spent 3.1 s of 6.5 s in `pop` before that.
pub(crate) struct Queue {
    /// The bucket being taken, and anything pushed below its end.
    active: BinaryHeap<Reverse<(u32, u32, u32, u32)>>,
    /// Keys below this go to `active`; the buckets below it are empty.
    active_end: u64,
    buckets: Vec<Vec<(u32, u32, u32, u32)>>,
    /// One bit per non-empty bucket.
    occupied: Vec<u64>,
    /// Entries in `buckets`.
    waiting: usize,
}

/// Key bits below the bucket index. Measured on the 1M scan (1% / 10%): 16 bits 1.58 / 1.48 s,
/// 18 bits 1.47 / 1.38 s, 20 bits 1.41 / 1.32 s, 22 bits 1.49 / 1.38 s.
const BUCKET_SHIFT: u32 = 20;
const BUCKETS: usize = 1 << (32 - BUCKET_SHIFT);

impl Queue {
    pub(crate) fn new() -> Queue {
        Queue {
            active: BinaryHeap::new(),
            active_end: 0,
            buckets: vec![Vec::new(); BUCKETS],
            occupied: vec![0; BUCKETS / 64],
            waiting: 0,
        }
    }

    pub(crate) fn push(&mut self, key: u32, a: u32, b: u32, stamp: u32) {
        if u64::from(key) < self.active_end {
            self.active.push(Reverse((key, a, b, stamp)));
        } else {
            let i = (key >> BUCKET_SHIFT) as usize;
            self.buckets[i].push((key, a, b, stamp));
            self.occupied[i / 64] |= 1 << (i % 64);
            self.waiting += 1;
        }
    }

    /// [`Queue::push`] of every entry of `parts`, each bucket's room made once first: grown
    /// entry by entry, the buckets were copied into new blocks again and again.
    pub(crate) fn push_all(&mut self, parts: &[Vec<(u32, u32, u32, u32)>]) {
        let mut count = vec![0usize; BUCKETS];
        for &(key, ..) in parts.iter().flatten() {
            if u64::from(key) >= self.active_end {
                count[(key >> BUCKET_SHIFT) as usize] += 1;
            }
        }
        for (bucket, &n) in self.buckets.iter_mut().zip(&count) {
            bucket.reserve(n);
        }
        for &(key, a, b, stamp) in parts.iter().flatten() {
            self.push(key, a, b, stamp);
        }
    }

    /// The entry with the smallest key; when a new bucket comes up, only its entries that are
    /// still `current` are kept.
    pub(crate) fn pop(
        &mut self,
        current: impl Fn(u32, u32, u32) -> bool,
    ) -> Option<(u32, u32, u32, u32)> {
        loop {
            if let Some(Reverse(e)) = self.active.pop() {
                return Some(e);
            }
            let from = (self.active_end >> BUCKET_SHIFT) as usize;
            let Some(i) = (from / 64..self.occupied.len()).find_map(|w| {
                let bits = self.occupied[w] & (!0u64 << (from.max(w * 64) - w * 64));
                (bits != 0).then(|| w * 64 + bits.trailing_zeros() as usize)
            }) else {
                // Empty: start again from the bottom, so a queue filled anew (the run re-queues
                // every edge before giving up) fills buckets rather than all go to the heap.
                self.active_end = 0;
                return None;
            };
            self.occupied[i / 64] &= !(1 << (i % 64));
            let list = std::mem::take(&mut self.buckets[i]);
            self.waiting -= list.len();
            self.active_end = ((i as u64) + 1) << BUCKET_SHIFT;
            // The heap is empty here: its allocation takes the bucket's live entries.
            let mut live = std::mem::take(&mut self.active).into_vec();
            live.clear();
            live.extend(
                list.into_iter()
                    .filter(|&(_, a, b, stamp)| current(a, b, stamp))
                    .map(Reverse),
            );
            self.active = BinaryHeap::from(live);
        }
    }

    /// The endpoints of the entry that comes out next, when it is already sorted (in the
    /// bucket being taken); `None` when the next pop opens a new bucket.
    pub(crate) fn peek(&self) -> Option<(u32, u32)> {
        self.active.peek().map(|Reverse((_, a, b, _))| (*a, *b))
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.active.is_empty() && self.waiting == 0
    }
}

/// Non-negative f64 priorities as f32 bits keep the heap entries 16 bytes; ordering of
/// non-negative IEEE floats equals ordering of their bit patterns.
pub(super) fn key(priority: f64) -> u32 {
    (priority as f32).to_bits()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The queue gives entries back in (key, a, b, stamp) order across buckets and within one,
    /// gives an entry pushed below the last key taken next, sorts entries pushed while it is
    /// being drained among the rest, and drops the entries of a bucket that are no longer
    /// current when that bucket comes up.
    #[test]
    fn queue_pops_in_key_order_and_drops_stale_entries() {
        // A deterministic spread of keys over many buckets and exponents, with ties.
        let keys: Vec<u32> = (0..5000u32)
            .map(|i| {
                (0.5 + (i.wrapping_mul(2_654_435_761) % 977) as f32 * 1e-3).to_bits() >> (i % 3)
            })
            .collect();
        let mut q = Queue::new();
        for (i, &k) in keys.iter().enumerate() {
            q.push(k, i as u32 % 7, i as u32, 0);
        }
        let mut expected: Vec<(u32, u32, u32, u32)> = keys
            .iter()
            .enumerate()
            .map(|(i, &k)| (k, i as u32 % 7, i as u32, 0))
            .collect();
        expected.sort_unstable();
        // Pushed while draining, as a run re-keys edges: above everything (the top bucket,
        // whose end is 2^32) and in the middle.
        let late = [
            (u32::MAX, 3, 4, 0),
            (0x8000_0000, 1, 2, 0),
            (keys[17], 8, 9, 0),
        ];
        expected.extend(late);
        expected.sort_unstable();
        let mut got = Vec::new();
        while let Some(e) = q.pop(|_, _, _| true) {
            got.push(e);
            if got.len() == 100 {
                // Below everything still queued (and below the last key taken): it must come
                // out next.
                let below = got[99].0 - 1;
                q.push(below, 0, u32::MAX, 9);
                assert_eq!(q.pop(|_, _, _| true), Some((below, 0, u32::MAX, 9)));
                for (k, a, b, stamp) in late {
                    q.push(k, a, b, stamp);
                }
            }
        }
        assert_eq!(got, expected);
        assert!(q.is_empty());
        // Filled again after running dry, it starts from the bottom.
        q.push(5, 0, 1, 0);
        q.push(3, 0, 2, 0);
        assert_eq!(q.pop(|_, _, _| true), Some((3, 0, 2, 0)));
        assert_eq!(q.pop(|_, _, _| true), Some((5, 0, 1, 0)));
        assert!(q.is_empty());

        // Odd stamps are stale: none of them comes out, every even one does.
        let mut q = Queue::new();
        for (i, &k) in keys.iter().enumerate() {
            q.push(k, 1, i as u32, i as u32 % 2);
        }
        let mut n = 0;
        while let Some((_, _, _, stamp)) = q.pop(|_, _, stamp| stamp == 0) {
            assert_eq!(stamp, 0);
            n += 1;
        }
        assert_eq!(n, keys.len().div_ceil(2));
        assert!(q.is_empty());
    }

    /// Pushing parts at once gives back what pushing each entry gives, into a fresh queue and
    /// into one being drained (entries below the bucket being taken go to its heap).
    #[test]
    fn push_all_equals_pushing_each_entry() {
        let entry = |i: u32| {
            let key = (1.0 + (i.wrapping_mul(2_654_435_761) % 613) as f32 * 1e-2).to_bits();
            (key >> (i % 4), i % 5, i, i % 3)
        };
        let parts: Vec<Vec<(u32, u32, u32, u32)>> = (0..7u32)
            .map(|p| (p * 300..p * 300 + 100 + 37 * p).map(entry).collect())
            .collect();
        let (mut one, mut all) = (Queue::new(), Queue::new());
        for &(k, a, b, s) in parts.iter().flatten() {
            one.push(k, a, b, s);
        }
        all.push_all(&parts);
        let mut taken = 0;
        loop {
            let e = one.pop(|_, _, _| true);
            assert_eq!(e, all.pop(|_, _, _| true));
            let Some((key, ..)) = e else { break };
            taken += 1;
            if taken == 50 {
                // Mid-drain: some of these fall below the bucket being taken.
                let late: Vec<Vec<_>> = vec![(5000..5100).map(entry).collect(), vec![]];
                for &(k, a, b, s) in late.iter().flatten() {
                    one.push(k.max(key), a, b, s);
                }
                let late: Vec<Vec<_>> = late
                    .into_iter()
                    .map(|p| {
                        p.into_iter()
                            .map(|(k, a, b, s)| (k.max(key), a, b, s))
                            .collect()
                    })
                    .collect();
                all.push_all(&late);
            }
        }
        assert!(taken > 150, "only {taken} entries came out");
        assert!(one.is_empty() && all.is_empty());
    }
}
