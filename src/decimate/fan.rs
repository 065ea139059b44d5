//! The fan of one vertex, gathered in winding order, and its class (Schroeder, Zarge & Lorensen
//! 1992, section 3.1): simple, boundary, interior edge, corner or complex. The class is computed
//! from the current faces every time the vertex is evaluated, so it stays current as the mesh
//! changes without a table to keep in step.

use glam::DVec3;

/// `topo` entry of a removed face.
pub(crate) const DEAD: u32 = u32::MAX;

/// Fans larger than this are treated as complex (kept): loop splitting is cubic in the loop's
/// length, and a scan's vertices have 4 to 12 faces even after 99% of them are gone.
pub(super) const MAX_FAN: usize = 40;

/// What a vertex is, and so whether and how it may go.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum VertexClass {
    /// A closed disk of faces without feature edges: removable, error against the fan's
    /// average plane.
    Simple,
    /// A half-disk on the border: removable (unless the border is locked and it is not on a
    /// straight stretch), error against the line through its two border neighbours.
    Boundary,
    /// A closed disk with exactly two feature edges (dihedral angle over the feature angle, an
    /// attribute seam, or a material change): removable along the feature line, error against
    /// the line through the two feature neighbours.
    InteriorEdge,
    /// One or three and more feature edges, or a border vertex that a feature edge also
    /// reaches: kept.
    Corner,
    /// Not manifold, a fan that is neither a disk nor a half-disk, a vertex a caller pinned, or
    /// a fan over [`MAX_FAN`] faces: kept.
    Complex,
}

impl VertexClass {
    pub fn name(self) -> &'static str {
        match self {
            VertexClass::Simple => "simple",
            VertexClass::Boundary => "boundary",
            VertexClass::InteriorEdge => "interior edge",
            VertexClass::Corner => "corner",
            VertexClass::Complex => "complex",
        }
    }

    pub fn removable(self) -> bool {
        matches!(
            self,
            VertexClass::Simple | VertexClass::Boundary | VertexClass::InteriorEdge
        )
    }
}

/// The faces around `v` in winding order: face `i` is `(v, x[i], x[i + 1])`; a closed fan has
/// as many loop vertices as faces (x wraps around), an open one (a border vertex) one more.
/// Reused from vertex to vertex: no allocation per evaluation once the buffers have grown.
#[derive(Default, Clone)]
pub(super) struct Fan {
    pub v: u32,
    pub class: Option<VertexClass>,
    pub closed: bool,
    /// Topological loop vertices.
    pub x: Vec<u32>,
    /// Face ids, in order.
    pub faces: Vec<u32>,
    /// Per face: the attribute vertices of its corners `(v, x[i], x[i + 1])`.
    pub attr: Vec<[u32; 3]>,
    /// Per face: unit normal (zero for a face without area), area and centroid (the centroid
    /// only summed over the fan when the average plane is asked for: computing it for every
    /// gathered fan was 5% of a run).
    pub normal: Vec<DVec3>,
    pub area: Vec<f64>,
    /// Indices `i` into `x` whose edge `(v, x[i])` is a feature edge (two for an interior edge).
    pub features: Vec<usize>,
    /// The live faces rotated to start at `v`: topological and attribute corners, face id.
    rot: Vec<([u32; 3], [u32; 3], u32)>,
}

/// What the fan needs to read from the mesh.
pub(super) struct FanInput<'a> {
    pub pos: &'a [[f64; 3]],
    /// Per face: topological corners (`DEAD` for a removed face) and attribute corners.
    pub topo: &'a [[u32; 3]],
    pub attr: &'a [[u32; 3]],
    /// Per face: its material and group id (`u32::MAX` when the mesh has none), so that a change
    /// of material counts as a feature edge.
    /// `None` when the mesh has neither (the lookups were 4% of a run).
    pub material: Option<&'a dyn Fn(u32) -> (u32, u32)>,
    /// Cosine of the feature angle: faces meeting at a smaller cosine make a feature edge.
    pub feature_cos: f64,
}

impl Fan {
    /// The centre's attribute vertices, each once (a seam or feature vertex has one per side).
    pub fn centre_attrs(&self) -> impl Iterator<Item = u32> + '_ {
        self.attr
            .iter()
            .enumerate()
            .filter(|&(i, c)| !self.attr[..i].iter().any(|d| d[0] == c[0]))
            .map(|(_, c)| c[0])
    }

    /// Loop vertex `x`'s attribute vertex on the side where the centre uses `a`, from a face of
    /// that side; `None` when no face of the side reaches `x`.
    pub fn attr_on_side(&self, a: u32, x: u32) -> Option<u32> {
        let nx = self.x.len();
        self.attr.iter().enumerate().find_map(|(j, c)| match () {
            _ if c[0] != a => None,
            _ if self.x[j] == x => Some(c[1]),
            _ if self.x[(j + 1) % nx] == x => Some(c[2]),
            _ => None,
        })
    }

    /// Gathers the fan of `v` from its live `faces` and classifies it. `held` (a caller's pin)
    /// makes it complex.
    pub fn gather(&mut self, v: u32, faces: &[u32], held: bool, m: &FanInput) {
        self.v = v;
        self.x.clear();
        self.faces.clear();
        self.attr.clear();
        self.normal.clear();
        self.area.clear();
        self.features.clear();
        self.class = Some(self.walk(v, faces, m));
        if held {
            self.class = Some(VertexClass::Complex);
        }
    }

    pub fn class(&self) -> VertexClass {
        self.class.unwrap_or(VertexClass::Complex)
    }

    /// Faces in the fan.
    pub fn len(&self) -> usize {
        self.faces.len()
    }

    fn walk(&mut self, v: u32, faces: &[u32], m: &FanInput) -> VertexClass {
        // Each live face rotated so that v comes first: (v, p, q) in winding order.
        self.rot.clear();
        for &f in faces {
            let t = m.topo[f as usize];
            if t[0] == DEAD {
                continue;
            }
            let a = m.attr[f as usize];
            let k = t.iter().position(|&c| c == v).unwrap_or(0);
            let r = [k, (k + 1) % 3, (k + 2) % 3];
            self.rot.push((r.map(|i| t[i]), r.map(|i| a[i]), f));
        }
        let live = self.rot.len();
        if live == 0 || live > MAX_FAN {
            return VertexClass::Complex;
        }
        // The start: a face whose p is no face's q (the first face of an open fan), else any.
        let rot = &self.rot;
        let start = (0..live)
            .find(|&i| !rot.iter().any(|r| r.0[2] == rot[i].0[1]))
            .unwrap_or(0);
        let mut cur = start;
        let mut seen = 0u64;
        loop {
            let (t, a, f) = self.rot[cur];
            seen |= 1 << cur;
            self.faces.push(f);
            self.x.push(t[1]);
            self.attr.push(a);
            let [p0, p1, p2] = t.map(|c| DVec3::from_array(m.pos[c as usize]));
            let c = (p1 - p0).cross(p2 - p0);
            let len = c.length();
            self.normal
                .push(if len > 0.0 { c / len } else { DVec3::ZERO });
            self.area.push(0.5 * len);
            let q = t[2];
            // The next face: the one whose p is this one's q. Two would make (v, q) non-manifold.
            let mut next = None;
            for (j, r) in self.rot.iter().enumerate() {
                if j != cur && r.0[1] == q {
                    if next.is_some() {
                        return VertexClass::Complex;
                    }
                    next = Some(j);
                }
            }
            match next {
                Some(j) if j == start => {
                    self.closed = true;
                    break;
                }
                Some(j) if seen & (1 << j) != 0 => return VertexClass::Complex,
                Some(j) => cur = j,
                None => {
                    self.closed = false;
                    self.x.push(q);
                    break;
                }
            }
        }
        // Faces left out of the walk: v has more than one fan (a bow-tie).
        if self.faces.len() != live {
            return VertexClass::Complex;
        }
        // A loop vertex met twice pinches the surface at it; the open fan's ends may not meet
        // either (that would be a closed fan whose edge is a border: non-manifold).
        for i in 0..self.x.len() {
            if self.x[i + 1..].contains(&self.x[i]) {
                return VertexClass::Complex;
            }
        }
        // Feature edges between consecutive faces: a dihedral angle over the limit, or the
        // faces disagreeing on an attribute vertex at either end of the edge (a seam), or on
        // the material or group.
        let n = self.faces.len();
        let inner = if self.closed { 0..n } else { 1..n };
        for i in inner {
            let prev = (i + n - 1) % n;
            let (a, b) = (self.attr[prev], self.attr[i]);
            let (na, nb) = (self.normal[prev], self.normal[i]);
            let sharp = na != DVec3::ZERO && nb != DVec3::ZERO && na.dot(nb) < m.feature_cos;
            // Face `prev` holds x[i] as its q (corner 2), face `i` as its p (corner 1).
            let seam = a[0] != b[0] || a[2] != b[1];
            let material = m
                .material
                .is_some_and(|mat| mat(self.faces[prev]) != mat(self.faces[i]));
            if sharp || seam || material {
                self.features.push(i);
            }
        }
        match (self.closed, self.features.len()) {
            (true, 0) if n >= 3 => VertexClass::Simple,
            (true, 2) if n >= 3 => VertexClass::InteriorEdge,
            (false, 0) if n >= 2 => VertexClass::Boundary,
            // A lone face's corner (its removal would delete the face and leave nothing) or a
            // closed fan of two faces (a degenerate pillow).
            (_, 0) => VertexClass::Complex,
            _ => VertexClass::Corner,
        }
    }

    /// The area-weighted average plane of the fan's faces `from..to`: unit normal and a point
    /// on it (Schroeder 1992's "average plane").
    pub fn average_plane(
        &self,
        pos: &[[f64; 3]],
        faces: impl Iterator<Item = usize>,
    ) -> (DVec3, DVec3) {
        let at = |x: u32| DVec3::from_array(pos[x as usize]);
        let pv = at(self.v);
        let m = self.x.len();
        let mut n = DVec3::ZERO;
        let mut c = DVec3::ZERO;
        let mut w = 0.0;
        for i in faces {
            let centroid = (pv + at(self.x[i]) + at(self.x[(i + 1) % m])) / 3.0;
            n += self.normal[i] * self.area[i];
            c += centroid * self.area[i];
            w += self.area[i];
        }
        let len = n.length();
        (
            if len > 0.0 { n / len } else { DVec3::ZERO },
            if w > 0.0 { c / w } else { c },
        )
    }
}
