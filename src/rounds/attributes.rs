//! The appearance channels the rounds carry: which (the greedy reference's [`Layout`]), each
//! attribute vertex's values weighted for the round's f32 buffers, and the solved values written
//! back into the output. The math is the stages' (shaders/rounds/attributes.inc.wgsl and its
//! twin src/rounds/cpu/attributes.rs).

use crate::compute::types::attr_layout;
use crate::mesh::Mesh;
use crate::options::AttributeWeights;
use crate::quadric::attributes::Layout;

/// The channels of a welded mesh the rounds carry, and their weighted values.
#[derive(Debug, Clone)]
pub struct RoundAttributes {
    pub(crate) layout: Layout,
    /// `m` weighted values (`weight · value`) per attribute vertex of the welded mesh.
    pub values: Vec<f32>,
}

impl RoundAttributes {
    /// The channels of `welded` with a weight above zero, or `None` when none has.
    pub fn new(welded: &Mesh, w: &AttributeWeights) -> Option<RoundAttributes> {
        let layout = Layout::new(welded, w)?;
        let m = layout.m;
        let mut values = vec![0.0f32; welded.positions.len() * m];
        for (v, out) in values.chunks_exact_mut(m).enumerate() {
            let mut put = |at: usize, x: f32| out[at] = (layout.weight[at] * f64::from(x)) as f32;
            if let Some(c) = &welded.colors {
                for (k, &x) in c[v].iter().enumerate().take(layout.color) {
                    put(k, x);
                }
            }
            if let (true, Some(t)) = (layout.uv, &welded.uvs) {
                put(layout.uv_at(), t[v][0]);
                put(layout.uv_at() + 1, t[v][1]);
            }
            if let (true, Some(n)) = (layout.normal, &welded.normals) {
                for (k, &x) in n[v].iter().enumerate() {
                    put(layout.normal_at() + k, x);
                }
            }
        }
        Some(RoundAttributes { layout, values })
    }

    pub fn channels(&self) -> usize {
        self.layout.m
    }

    /// `Params::attributes` and `Params::color_weight`.
    pub fn params(&self) -> (u32, f32) {
        let l = &self.layout;
        let packed = attr_layout::pack(l.m as u32, l.color as u32, l.uv);
        (packed, if l.color > 0 { l.weight[0] as f32 } else { 0.0 })
    }

    /// Numbers of the attribute sums of every attribute vertex.
    pub fn sums_len(&self) -> usize {
        self.values.len() / self.layout.m * (4 * self.layout.m + 1)
    }

    /// Writes the values the rounds `solved` into `out` (the welded mesh's attribute vertices,
    /// before unused ones are dropped): those a collapse changed, unweighted; colours clamped to
    /// 0..1 against rounding, normals renormalised. Untouched values stay bit for bit.
    pub fn write(&self, solved: &[f32], out: &mut Mesh) {
        let l = &self.layout;
        let m = l.m;
        let changed = self
            .values
            .chunks_exact(m)
            .zip(solved.chunks_exact(m))
            .enumerate()
            .filter(|(_, (a, b))| a != b);
        let un = |x: f32, j: usize| (f64::from(x) / l.weight[j]) as f32;
        for (v, (_, s)) in changed {
            if let Some(c) = &mut out.colors {
                for k in 0..l.color {
                    c[v][k] = un(s[k], k).clamp(0.0, 1.0);
                }
            }
            if let (true, Some(t)) = (l.uv, &mut out.uvs) {
                let at = l.uv_at();
                t[v] = [un(s[at], at), un(s[at + 1], at + 1)];
            }
            if let (true, Some(nr)) = (l.normal, &mut out.normals) {
                let at = l.normal_at();
                let n = [0, 1, 2].map(|k| un(s[at + k], at + k));
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                if len > 0.0 && len.is_finite() {
                    nr[v] = n.map(|x| x / len);
                }
            }
        }
    }

    /// Whether the output's normals are the solved ones (a normal weight above zero).
    pub fn keeps_normals(&self) -> bool {
        self.layout.normal
    }
}
