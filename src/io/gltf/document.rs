//! A parsed glTF document with its buffers, and reading its accessors: checked bounds, strides
//! and types, so that no hostile file makes the reader panic or read out of bounds.

use std::path::Path;

use gltf::json;
use json::validation::Checked;
use serde_json::Value;

use crate::error::{Error, Location, Result};

pub(super) struct Doc<'a> {
    pub(super) root: json::Root,
    /// Materials, textures, samplers and images as raw JSON: carried through unchanged
    /// (`json::Root` drops the extensions it does not know).
    pub(super) carried: RawAppearance,
    pub(super) buffers: Vec<Vec<u8>>,
    pub(super) path: &'a Path,
}

/// The input's materials, textures, samplers, images and required extensions as raw JSON,
/// for the writer to carry through.
#[derive(serde::Deserialize, Default)]
#[serde(default, rename_all = "camelCase")]
pub(super) struct RawAppearance {
    pub(super) materials: Vec<Value>,
    pub(super) textures: Vec<Value>,
    pub(super) samplers: Vec<Value>,
    pub(super) images: Vec<Value>,
    pub(super) extensions_required: Vec<String>,
}

impl Doc<'_> {
    pub(super) fn err(&self, m: impl Into<String>) -> Error {
        Error::parse(self.path, Location::Unknown, m)
    }

    /// Instancing lets a tiny file place one mesh a million times: what the scene expands to is
    /// bounded by the data actually present. 64 elements per buffer byte is far beyond any real
    /// scene's instancing, and with the 1M floor a few GiB at most.
    pub(super) fn check_expansion(&self, total: usize, what: &str) -> Result<()> {
        let data: usize = self.buffers.iter().map(Vec::len).sum();
        let limit = data.saturating_mul(64).max(1 << 20);
        if total > limit {
            return Err(self.err(format!(
                "the scene instantiates more than {limit} {what} from {data} bytes of buffers; \
                 refusing to expand it further"
            )));
        }
        Ok(())
    }

    /// The bytes of accessor `i` and its layout: (data, stride, element size, count).
    fn accessor_bytes(
        &self,
        i: usize,
        what: &str,
    ) -> Result<(&[u8], usize, usize, usize, &json::Accessor)> {
        let acc = self
            .root
            .accessors
            .get(i)
            .ok_or_else(|| self.err(format!("{what}: accessor {i} does not exist")))?;
        if acc.sparse.is_some() {
            return Err(self.err(format!(
                "{what}: accessor {i} is sparse, which is not supported"
            )));
        }
        let (Checked::Valid(ct), Checked::Valid(ty)) = (&acc.component_type, &acc.type_) else {
            return Err(self.err(format!("{what}: accessor {i} has an invalid type")));
        };
        let elem = ct.0.size() * ty.multiplicity();
        let count = acc.count.0 as usize;
        let view_i = acc
            .buffer_view
            .as_ref()
            .ok_or_else(|| {
                self.err(format!(
                    "{what}: accessor {i} has no buffer view, which is not supported"
                ))
            })?
            .value();
        let view = self
            .root
            .buffer_views
            .get(view_i)
            .ok_or_else(|| self.err(format!("{what}: buffer view {view_i} does not exist")))?;
        let buf = self.buffers.get(view.buffer.value()).ok_or_else(|| {
            self.err(format!(
                "{what}: buffer {} does not exist",
                view.buffer.value()
            ))
        })?;
        let vstart = view.byte_offset.map_or(0, |o| o.0);
        let vdata = vstart
            .checked_add(view.byte_length.0)
            .and_then(|end| buf.get(usize::try_from(vstart).ok()?..usize::try_from(end).ok()?))
            .ok_or_else(|| {
                self.err(format!(
                    "{what}: buffer view {view_i} lies outside its buffer"
                ))
            })?;
        let stride = view.byte_stride.as_ref().map_or(elem, |s| s.0);
        if stride < elem {
            return Err(self.err(format!(
                "{what}: buffer view {view_i} has stride {stride}, smaller than the {elem}-byte element"
            )));
        }
        if count == 0 {
            return Ok((&[], stride, elem, 0, acc));
        }
        let start = acc.byte_offset.map_or(0, |o| o.0) as usize;
        let data = (count - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(elem))
            .and_then(|x| x.checked_add(start))
            .and_then(|end| vdata.get(start..end))
            .ok_or_else(|| {
                self.err(format!("{what}: accessor {i} ({count} elements) runs past the end of buffer view {view_i}"))
            })?;
        Ok((data, stride, elem, count, acc))
    }

    /// Float components of accessor `i` (normalised integers mapped to 0..1 / -1..1), checking
    /// that it has `dims` (one of) components.
    pub(super) fn floats(&self, i: usize, dims: &[usize], what: &str) -> Result<(Vec<f32>, usize)> {
        let (data, stride, _, count, acc) = self.accessor_bytes(i, what)?;
        let (Checked::Valid(ct), Checked::Valid(ty)) = (&acc.component_type, &acc.type_) else {
            return Err(self.err(format!("{what}: accessor {i} has an invalid type")));
        };
        let n = ty.multiplicity();
        if !dims.contains(&n) {
            return Err(self.err(format!(
                "{what}: accessor {i} has {n} components, expected {dims:?}"
            )));
        }
        use json::accessor::ComponentType as C;
        let ct = ct.0;
        if ct != C::F32 && !acc.normalized {
            return Err(self.err(format!(
                "{what}: accessor {i} has non-normalised integer components"
            )));
        }
        let size = ct.size();
        let mut out = Vec::with_capacity(count * n);
        for e in 0..count {
            let el = &data[e * stride..];
            for k in 0..n {
                let b = &el[k * size..];
                let v = match ct {
                    C::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                    C::U8 => b[0] as f32 / 255.0,
                    C::I8 => (b[0] as i8 as f32 / 127.0).max(-1.0),
                    C::U16 => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
                    C::I16 => (i16::from_le_bytes([b[0], b[1]]) as f32 / 32767.0).max(-1.0),
                    C::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32 / u32::MAX as f32,
                };
                out.push(v);
            }
        }
        Ok((out, n))
    }

    pub(super) fn indices(&self, i: usize, what: &str) -> Result<Vec<u32>> {
        let (data, stride, _, count, acc) = self.accessor_bytes(i, what)?;
        use json::accessor::{ComponentType as C, Type};
        let (Checked::Valid(ct), Checked::Valid(Type::Scalar)) = (&acc.component_type, &acc.type_)
        else {
            return Err(self.err(format!("{what}: index accessor {i} is not a scalar")));
        };
        let mut out = Vec::with_capacity(count);
        for e in 0..count {
            let b = &data[e * stride..];
            out.push(match ct.0 {
                C::U8 => b[0] as u32,
                C::U16 => u16::from_le_bytes([b[0], b[1]]) as u32,
                C::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                other => {
                    return Err(self.err(format!(
                        "{what}: index accessor {i} has component type {other:?}"
                    )));
                }
            });
        }
        Ok(out)
    }
}
