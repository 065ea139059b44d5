//! Sorting integer keys on every core: the stable radix sort the clustering's builds and the
//! Morton order of every set-up use.

use rayon::prelude::*;

/// `radix_sort`: the ids `0..n` of `keys` ordered by key, stable (so by (key, id)), and the keys
/// in that order: least significant digit first, as many passes as the largest key needs. The
/// order is unique, so this is the GPU's result whatever the digit: the GPU sorts 8 bits a pass
/// (tests/cluster_twins has its pass-for-pass twin), this 11 (2,048 counters stay in the L1
/// cache): 2 passes for the 1M meshes' 17-18-bit keys at 1%, where 8-bit digits take 3 (their
/// 23-24-bit keys at 10% take 3 either way; two of 12 bits were no faster).
///
/// Each pass runs on every core: the keys are cut into [`RADIX_CHUNKS`] runs, each counts its
/// digits, and each then writes its keys, in order, into its own slice of every digit's range
/// (the digit's slices in run order): stable, so the same order. The 1M scan's cell keys at
/// 10%: 0.008-0.015 s on one core, 0.006-0.009 s on two. (1M keys in random order, whose
/// scatter is bound by memory rather than by a core, sorted no faster this way.)
/// The first pass reads `keys` where they are, each id its index, and their block is the
/// second pass's target: copying them out first wrote 2 MB more of fresh pages on the 1M
/// meshes, each 4 KiB a fault (about 2.7 µs on the 2-core VM).
pub fn radix_sort(keys: Vec<u32>) -> (Vec<u32>, Vec<u32>) {
    let n = keys.len();
    let max = keys.par_iter().copied().max().unwrap_or(0);
    let bits = 32 - max.leading_zeros();
    let mut k = keys;
    // The ids, `0..n` before the first pass, which writes them (so nothing is held here).
    let mut v: Vec<u32> = Vec::new();
    let mut k2 = vec![0u32; n];
    let mut v2 = vec![0u32; n];
    const DIGIT: u32 = 11;
    const MASK: u32 = (1 << DIGIT) - 1;
    const D: usize = MASK as usize + 1;
    let runs = if n < RADIX_PARALLEL_MIN {
        1
    } else {
        RADIX_CHUNKS
    };
    let run = n.div_ceil(runs).max(1);
    let passes = bits.div_ceil(DIGIT);
    if passes == 0 {
        return (k, (0..n as u32).into_par_iter().collect());
    }
    for pass in 0..passes {
        let shift = DIGIT * pass;
        let digit = |x: u32| ((x >> shift) & MASK) as usize;
        let counts: Vec<Vec<usize>> = k
            .par_chunks(run)
            .map(|part| {
                let mut c = vec![0usize; D];
                for &x in part {
                    c[digit(x)] += 1;
                }
                c
            })
            .collect();
        // The output cut digit by digit, each digit's range run by run.
        let mut outs: Vec<Vec<(&mut [u32], &mut [u32])>> =
            (0..counts.len()).map(|_| Vec::with_capacity(D)).collect();
        let (mut krest, mut vrest) = (&mut k2[..], &mut v2[..]);
        for d in 0..D {
            for (r, c) in counts.iter().enumerate() {
                let (kh, kt) = std::mem::take(&mut krest).split_at_mut(c[d]);
                let (vh, vt) = std::mem::take(&mut vrest).split_at_mut(c[d]);
                outs[r].push((kh, vh));
                (krest, vrest) = (kt, vt);
            }
        }
        let ids = &v;
        k.par_chunks(run)
            .enumerate()
            .zip(outs)
            .for_each(|((r, ks), mut out)| {
                let mut at = vec![0usize; D];
                for (j, &x) in ks.iter().enumerate() {
                    let i = r * run + j;
                    let id = if pass == 0 { i as u32 } else { ids[i] };
                    let d = digit(x);
                    out[d].0[at[d]] = x;
                    out[d].1[at[d]] = id;
                    at[d] += 1;
                }
            });
        std::mem::swap(&mut k, &mut k2);
        std::mem::swap(&mut v, &mut v2);
        if pass == 0 && passes > 1 {
            v2 = vec![0u32; n];
        }
    }
    (k, v)
}

/// Runs a [`radix_sort`] pass is cut into: a fixed number, whatever the thread count (the
/// order is the same for any).
const RADIX_CHUNKS: usize = 8;
/// Below this many keys one run does the passes.
const RADIX_PARALLEL_MIN: usize = 1 << 16;
