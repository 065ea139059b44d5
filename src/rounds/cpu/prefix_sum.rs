//! Twin of shaders/core/prefix_sum.wgsl: exclusive prefix sum of `n` u32 values in place, the total
//! written at index `n`, in three stages — per-block sums, a scan of the block sums, and each
//! block's local scan plus its offset. Integer results equal the GPU's exactly.

use crate::compute::types::SCAN_BLOCK;
use rayon::prelude::*;

pub fn blocks(n: u32) -> u32 {
    n.div_ceil(SCAN_BLOCK).max(1)
}

/// Per workgroup: the sum of its block of `SCAN_BLOCK` elements.
pub fn prefix_sum_reduce(n: u32, data: &[u32], block_sums: &mut [u32]) {
    let b = SCAN_BLOCK as usize;
    block_sums[..blocks(n) as usize]
        .par_iter_mut()
        .enumerate()
        .for_each(|(wg, s)| {
            let lo = (wg * b).min(n as usize);
            let hi = ((wg + 1) * b).min(n as usize);
            *s = data[lo..hi].iter().fold(0u32, |a, &x| a.wrapping_add(x));
        });
}

/// One workgroup: exclusive scan of the block sums; the grand total goes to `data[n]`.
pub fn prefix_sum_spine(n: u32, block_sums: &mut [u32], data: &mut [u32]) {
    let mut run = 0u32;
    for s in &mut block_sums[..blocks(n) as usize] {
        let x = *s;
        *s = run;
        run = run.wrapping_add(x);
    }
    data[n as usize] = run;
}

/// Per workgroup: exclusive scan of its block, offset by the block's scanned sum.
pub fn prefix_sum_apply(n: u32, block_sums: &[u32], data: &mut [u32]) {
    let b = SCAN_BLOCK as usize;
    data[..n as usize]
        .par_chunks_mut(b)
        .enumerate()
        .for_each(|(wg, chunk)| {
            let mut run = block_sums[wg];
            for x in chunk {
                let v = *x;
                *x = run;
                run = run.wrapping_add(v);
            }
        });
}

/// The three stages in order; `data` holds `n + 1` values. Returns the total.
pub fn prefix_sum(n: u32, data: &mut [u32], block_sums: &mut Vec<u32>) -> u32 {
    assert!(
        data.len() > n as usize,
        "prefix sum buffer holds n + 1 values"
    );
    block_sums.resize(blocks(n) as usize, 0);
    prefix_sum_reduce(n, data, block_sums);
    prefix_sum_spine(n, block_sums, data);
    prefix_sum_apply(n, block_sums, data);
    data[n as usize]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scans_across_blocks() {
        for n in [0u32, 1, 5, 1024, 1025, 5000] {
            let mut data: Vec<u32> = (0..=n).map(|i| i % 7).collect();
            let expect: Vec<u32> = data[..n as usize]
                .iter()
                .scan(0, |s, &x| {
                    let r = *s;
                    *s += x;
                    Some(r)
                })
                .collect();
            let total: u32 = data[..n as usize].iter().sum();
            let mut sums = Vec::new();
            assert_eq!(prefix_sum(n, &mut data, &mut sums), total);
            assert_eq!(&data[..n as usize], &expect[..]);
        }
    }
}
