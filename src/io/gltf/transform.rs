//! Node transforms: 4×4 matrices (column-major) from a node's matrix or TRS, their product, and
//! the normal matrix.

use gltf::json;

pub(super) type Mat = [[f64; 4]; 4]; // column-major: m[col][row]

pub(super) const IDENTITY: Mat = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

pub(super) fn mul(a: &Mat, b: &Mat) -> Mat {
    let mut m = [[0.0; 4]; 4];
    for (c, col) in m.iter_mut().enumerate() {
        for (r, x) in col.iter_mut().enumerate() {
            *x = (0..4).map(|k| a[k][r] * b[c][k]).sum();
        }
    }
    m
}

pub(super) fn local_matrix(n: &json::Node) -> Mat {
    if let Some(m) = n.matrix {
        let mut out = [[0.0; 4]; 4];
        for c in 0..4 {
            for r in 0..4 {
                out[c][r] = m[c * 4 + r] as f64;
            }
        }
        return out;
    }
    let t = n.translation.unwrap_or([0.0; 3]).map(f64::from);
    let [x, y, z, w] = n
        .rotation
        .as_ref()
        .map_or([0.0, 0.0, 0.0, 1.0], |q| q.0)
        .map(f64::from);
    let s = n.scale.unwrap_or([1.0; 3]).map(f64::from);
    let r = [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y + z * w),
            2.0 * (x * z - y * w),
        ],
        [
            2.0 * (x * y - z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z + x * w),
        ],
        [
            2.0 * (x * z + y * w),
            2.0 * (y * z - x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ];
    let mut m = IDENTITY;
    for c in 0..3 {
        for k in 0..3 {
            m[c][k] = r[c][k] * s[c];
        }
    }
    m[3][..3].copy_from_slice(&t);
    m
}

pub(super) fn det3(m: &Mat) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2])
        - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2])
}

/// Inverse transpose of the upper 3×3 (as a 3×3 column-major), for normals.
#[allow(clippy::needless_range_loop)]
pub(super) fn normal_matrix(m: &Mat) -> [[f64; 3]; 3] {
    let d = det3(m);
    let d = if d == 0.0 { 1.0 } else { d };
    // Cofactor matrix / det = inverse transpose.
    let a = |c: usize, r: usize| m[c][r];
    let mut n = [[0.0; 3]; 3];
    for c in 0..3 {
        for r in 0..3 {
            let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
            let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
            n[c][r] = (a(c1, r1) * a(c2, r2) - a(c1, r2) * a(c2, r1)) / d;
        }
    }
    n
}
