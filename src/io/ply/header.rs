//! The PLY header: the encoding, the elements and their properties, parsed line by line; and
//! the scalar types PLY names, with how each is decoded from binary or ascii.

use std::io::{BufRead, Read};
use std::path::Path;

use crate::error::{Error, Location, Result};

/// Encoding of a PLY file body.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlyEncoding {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }
    pub(super) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }
    /// Divisor that maps an integer colour channel to 0..=1.
    pub(super) fn color_scale(self) -> f64 {
        match self {
            Scalar::I8 => 127.0,
            Scalar::U8 => 255.0,
            Scalar::I16 => 32767.0,
            Scalar::U16 => 65535.0,
            Scalar::I32 => i32::MAX as f64,
            Scalar::U32 => u32::MAX as f64,
            Scalar::F32 | Scalar::F64 => 1.0,
        }
    }
    #[inline]
    pub(super) fn decode(self, b: &[u8], big: bool) -> f64 {
        macro_rules! get {
            ($t:ty, $n:expr) => {{
                let mut a = [0u8; $n];
                a.copy_from_slice(&b[..$n]);
                (if big {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                }) as f64
            }};
        }
        match self {
            Scalar::I8 => b[0] as i8 as f64,
            Scalar::U8 => b[0] as f64,
            Scalar::I16 => get!(i16, 2),
            Scalar::U16 => get!(u16, 2),
            Scalar::I32 => get!(i32, 4),
            Scalar::U32 => get!(u32, 4),
            Scalar::F32 => get!(f32, 4),
            Scalar::F64 => get!(f64, 8),
        }
    }
    /// Parses an ascii token of this type, widened to f64 without loss. `float` tokens are parsed
    /// as f32 directly, so a value written with Rust's `{}` comes back bit-exact.
    pub(super) fn parse_token(self, t: &str) -> Option<f64> {
        match self {
            Scalar::F32 => t.parse::<f32>().ok().map(f64::from),
            Scalar::F64 => t.parse::<f64>().ok(),
            _ => {
                let v = t.parse::<i64>().ok()?;
                let (lo, hi) = match self {
                    Scalar::I8 => (i8::MIN as i64, i8::MAX as i64),
                    Scalar::U8 => (0, u8::MAX as i64),
                    Scalar::I16 => (i16::MIN as i64, i16::MAX as i64),
                    Scalar::U16 => (0, u16::MAX as i64),
                    Scalar::I32 => (i32::MIN as i64, i32::MAX as i64),
                    _ => (0, u32::MAX as i64),
                };
                (lo..=hi).contains(&v).then_some(v as f64)
            }
        }
    }
}

#[derive(Debug, Clone, Copy)]
pub(super) enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug)]
pub(super) struct Property {
    pub(super) name: String,
    pub(super) kind: Kind,
}

#[derive(Debug)]
pub(super) struct Element {
    pub(super) name: String,
    pub(super) count: u64,
    pub(super) props: Vec<Property>,
    /// Header line that declared the element.
    pub(super) line: u64,
}

impl Element {
    /// Fewest bytes one element can take in a binary body (a list may be empty).
    pub(super) fn min_binary_bytes(&self) -> u64 {
        self.props
            .iter()
            .map(|p| match p.kind {
                Kind::Scalar(s) => s.size() as u64,
                Kind::List { count, .. } => count.size() as u64,
            })
            .sum()
    }
    /// Fixed record size when the element has no list property.
    pub(super) fn fixed_size(&self) -> Option<usize> {
        self.props
            .iter()
            .map(|p| match p.kind {
                Kind::Scalar(s) => Some(s.size()),
                Kind::List { .. } => None,
            })
            .sum()
    }
}

pub(super) struct Header {
    pub(super) encoding: PlyEncoding,
    pub(super) elements: Vec<Element>,
    /// Bytes up to and including the `end_header` line.
    pub(super) len: u64,
    /// Number of header lines.
    pub(super) lines: u64,
}

/// Longest header accepted; real headers are a few hundred bytes.
const MAX_HEADER: u64 = 1 << 20;

pub(super) fn read_header(r: &mut impl BufRead, path: &Path) -> Result<Header> {
    let mut buf = Vec::new();
    let mut len = 0u64;
    let mut line_no = 0u64;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        buf.clear();
        let n = r
            .by_ref()
            .take(MAX_HEADER.saturating_sub(len).max(1))
            .read_until(b'\n', &mut buf)
            .map_err(|e| Error::io(path, e))?;
        line_no += 1;
        len += n as u64;
        let at = Location::Line(line_no);
        if n == 0 {
            return Err(Error::parse(
                path,
                at,
                if line_no == 1 {
                    "empty file".to_string()
                } else {
                    "end of file inside the PLY header (no end_header line)".to_string()
                },
            ));
        }
        if buf.last() != Some(&b'\n') && len >= MAX_HEADER {
            return Err(Error::parse(
                path,
                at,
                "PLY header longer than 1 MiB or missing end_header",
            ));
        }
        let text = String::from_utf8_lossy(&buf);
        let text = text.trim_end_matches(['\n', '\r']);
        let mut words = text.split_ascii_whitespace();
        let first = words.next();
        if line_no == 1 {
            if text.trim() != "ply" {
                return Err(Error::parse(
                    path,
                    at,
                    "not a PLY file: the first line must be \"ply\"",
                ));
            }
            continue;
        }
        match first {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                let e = match words.next() {
                    Some("ascii") => PlyEncoding::Ascii,
                    Some("binary_little_endian") => PlyEncoding::BinaryLittleEndian,
                    Some("binary_big_endian") => PlyEncoding::BinaryBigEndian,
                    other => {
                        return Err(Error::parse(
                            path,
                            at,
                            format!("unknown PLY format {:?}", other.unwrap_or("")),
                        ));
                    }
                };
                encoding = Some(e);
            }
            Some("element") => {
                let (Some(name), Some(count), None) = (words.next(), words.next(), words.next())
                else {
                    return Err(Error::parse(path, at, "expected \"element NAME COUNT\""));
                };
                let count: u64 = count.parse().map_err(|_| {
                    Error::parse(path, at, format!("element {name}: bad count {count:?}"))
                })?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                    line: line_no,
                });
            }
            Some("property") => {
                let Some(el) = elements.last_mut() else {
                    return Err(Error::parse(path, at, "property before any element"));
                };
                let ty = |s: Option<&str>| -> Result<Scalar> {
                    let s = s.unwrap_or("");
                    Scalar::parse(s).ok_or_else(|| {
                        Error::parse(path, at, format!("unknown property type {s:?}"))
                    })
                };
                let w: Vec<&str> = words.collect();
                let (kind, name) = match w.as_slice() {
                    ["list", c, i, name] => (
                        Kind::List {
                            count: ty(Some(c))?,
                            item: ty(Some(i))?,
                        },
                        name,
                    ),
                    [t, name] => (Kind::Scalar(ty(Some(t))?), name),
                    _ => {
                        return Err(Error::parse(
                            path,
                            at,
                            "expected \"property TYPE NAME\" or \"property list COUNT_TYPE ITEM_TYPE NAME\"",
                        ));
                    }
                };
                if let Kind::List { count, .. } = kind
                    && count.is_float()
                {
                    return Err(Error::parse(
                        path,
                        at,
                        "a list count must have an integer type",
                    ));
                }
                el.props.push(Property {
                    name: name.to_string(),
                    kind,
                });
            }
            Some("end_header") => {
                let encoding = encoding
                    .ok_or_else(|| Error::parse(path, at, "PLY header has no format line"))?;
                return Ok(Header {
                    encoding,
                    elements,
                    len,
                    lines: line_no,
                });
            }
            Some(other) => {
                return Err(Error::parse(
                    path,
                    at,
                    format!("unexpected header keyword {other:?}"),
                ));
            }
        }
    }
}
