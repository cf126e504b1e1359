//! One visit of the decimation (paper section 4.1): a free vertex tries its neighbours in
//! increasing cone volume and performs the first valid half-edge collapse ([`choose_collapse`]),
//! reading the level and the pass state through a [`PassView`]. A hot kernel: the validity
//! checks stay in one function so that a visit reads the fans once.

use super::*;

/// Visits `v`: if it is free and may go, performs its first valid collapse and returns the target
/// and the six split volume.
pub(super) fn visit(v: u32, view: &PassView, scratch: &mut Scratch) -> Option<(u32, f32)> {
    if view.mark[v as usize].load(Relaxed) != FREE {
        return None;
    }
    let open = view.open[v as usize];
    if open && view.keep_boundary
        || view
            .pinned
            .get(view.vertex_id[v as usize] as usize)
            .is_some_and(|&p| p)
    {
        return None;
    }
    // A crease vertex collapses only along its crease; a corner never. Nor when its crease
    // neighbours are joined by an edge already: a loop of three would close on itself, and where a
    // face holds the three (a noisy crease zigzags), the split would put the vertex back between
    // the other two, on their line, and leave that face with no area.
    let crease_of = |u: u32| view.crease[u as usize].each_ref().map(|c| c.load(Relaxed));
    let along = if view.crease.is_empty() {
        NO_CREASE
    } else {
        crease_of(v)
    };
    if along == CORNER
        || along != NO_CREASE
            && (crease_of(along[0]).contains(&along[1])
                || view
                    .fan(v)
                    .iter()
                    .any(|&[a, b]| along == [a, b] || along == [b, a]))
    {
        return None;
    }
    let along = (along != NO_CREASE).then_some(along);
    let (k, six_volume) = choose_collapse(v, open, along, view, scratch)?;
    if let Some([a, b]) = along {
        // The crease now runs w - k.
        let w = if k == a { b } else { a };
        for (x, from, to) in [(k, v, w), (w, v, k)] {
            for slot in &view.crease[x as usize] {
                if slot.load(Relaxed) == from {
                    slot.store(to, Relaxed);
                }
            }
        }
    }
    // Perform v -> k: faces are relabelled when the next level is built (a pass's collapses touch
    // disjoint face sets, so they compose as one simultaneous relabelling).
    view.mark[v as usize].store(k, Relaxed);
    for &x in &scratch.neighbors {
        view.mark[x as usize].store(LOCKED, Relaxed);
    }
    let head = view.absorbed_head[k as usize].load(Relaxed);
    view.absorbed_next[v as usize].store(head, Relaxed);
    view.absorbed_head[k as usize].store(v, Relaxed);
    Some((k, six_volume as f32))
}

/// The level and the pass state as visits see them.
pub(super) struct PassView<'a> {
    points: &'a [[f32; 3]],
    vertex_id: &'a [u32],
    fan_offsets: &'a [u32],
    fans: &'a [[u32; 2]],
    open: &'a [bool],
    /// Per M0 id, empty when nothing is pinned.
    pinned: &'a [bool],
    /// M0's vertex normals by M0 id; empty when collapses may turn faces against them.
    m0_normals: &'a [[f32; 3]],
    keep_boundary: bool,
    mark: &'a [AtomicU32],
    absorbed_head: &'a [AtomicU32],
    absorbed_next: &'a [AtomicU32],
    crease: &'a [[AtomicU32; 2]],
}

impl<'a> PassView<'a> {
    pub(super) fn new(
        level: &'a Level,
        state: &'a PassState,
        pinned: &'a [bool],
        m0_normals: &'a [[f32; 3]],
        keep_boundary: bool,
    ) -> Self {
        PassView {
            points: &level.points,
            vertex_id: &level.vertex_id,
            fan_offsets: &state.fan_offsets,
            fans: &state.fans,
            open: &state.open,
            pinned,
            m0_normals,
            keep_boundary,
            mark: &state.mark,
            absorbed_head: &state.absorbed_head,
            absorbed_next: &state.absorbed_next,
            crease: &state.crease,
        }
    }
}

impl PassView<'_> {
    #[inline]
    fn fan(&self, v: u32) -> &[[u32; 2]] {
        &self.fans[self.fan_offsets[v as usize] as usize..self.fan_offsets[v as usize + 1] as usize]
    }

    /// The current label of a vertex of the level: its target if removed in this pass.
    #[inline]
    fn current(&self, c: u32) -> u32 {
        let m = self.mark[c as usize].load(Relaxed);
        if m < LOCKED {
            m
        } else {
            c
        }
    }

    /// Calls `visit` with the two other corners of every live face of `k`: its faces at the start
    /// of the pass, relabelled by this pass's collapses (a face that degenerates is gone), and
    /// those of the vertices collapsed into it during this pass.
    #[inline]
    fn for_each_face_of(&self, k: u32, mut visit: impl FnMut(u32, u32)) {
        for &[a, b] in self.fan(k) {
            let (a, b) = (self.current(a), self.current(b));
            if a != b && a != k && b != k {
                visit(a, b);
            }
        }
        let mut absorbed = self.absorbed_head[k as usize].load(Relaxed);
        while absorbed != NEVER {
            for &[a, b] in self.fan(absorbed) {
                // The absorbed vertex's neighbours were locked when it went: they are unchanged.
                if a != k && b != k {
                    visit(a, b);
                }
            }
            absorbed = self.absorbed_next[absorbed as usize].load(Relaxed);
        }
    }
}

#[derive(Default)]
pub(super) struct Scratch {
    neighbors: Vec<u32>,
    /// Positions of `a` and `b` relative to `v` for each face `(v, a, b)` of the vertex being
    /// tried.
    positions: Vec<[DVec3; 2]>,
    /// The normal (x_a - x_v) x (x_b - x_v) of each of those faces.
    normals: Vec<DVec3>,
    /// The faces `(k, a, b)` a candidate collapse leaves, with their normals.
    after: Vec<([u32; 2], DVec3)>,
    /// Those and `k`'s other faces: `k`'s one-ring after the collapse.
    ring: Vec<([u32; 2], DVec3)>,
    /// `(|cone|, k, signed cone)`.
    candidates: Vec<(f64, u32, f64)>,
    /// Scratch space of `in_cost_order`.
    pub(super) keys: Vec<[u32; 2]>,
}

/// The first valid collapse target of `v` (on a boundary if `on_boundary`; one of `along` when
/// it is on a crease) in increasing cone volume, with its signed cone volume.
pub(super) fn choose_collapse(
    v: u32,
    on_boundary: bool,
    along: Option<[u32; 2]>,
    view: &PassView,
    scratch: &mut Scratch,
) -> Option<(u32, f64)> {
    let m0_id = view.vertex_id;
    let fan = view.fan(v);
    if fan.is_empty() {
        return None;
    }
    let p = |c: u32| point(view.points, c);
    // An open fan starts with an edge v-a (a first in its face) that no face has as v-b and ends
    // with one v-b that no face has as v-a.
    let mut fan_start = NEVER;
    let mut fan_end = NEVER;
    if on_boundary {
        for &[a, _] in fan {
            if !fan.iter().any(|&[_, b]| b == a) {
                fan_start = a;
            }
        }
        for &[_, b] in fan {
            if !fan.iter().any(|&[a, _]| a == b) {
                fan_end = b;
            }
        }
    }
    // Positions relative to `x_v` (exact: differences of f32 values are f64 values), and the
    // fan's area vector N = sum over v's faces of (x_a - x_v) x (x_b - x_v), each term kept as
    // the face's normal before the collapse.
    let xv = p(v);
    scratch.neighbors.clear();
    scratch.positions.clear();
    scratch.normals.clear();
    let mut area = DVec3::ZERO;
    for &[a, b] in fan {
        scratch.neighbors.push(a);
        let (xa, xb) = (p(a) - xv, p(b) - xv);
        let normal = xa.cross(xb);
        area += normal;
        scratch.positions.push([xa, xb]);
        scratch.normals.push(normal);
    }
    if on_boundary {
        scratch.neighbors.push(fan_end);
    }

    // Cone volumes. With x_v at the origin a face's term is ((a - k) x (b - k)) . (-k), and
    // (a - k) x (b - k) = a x b - a x k - k x b, whose last two parts are orthogonal to k; so
    // the cone is -N . (x_k - x_v) for every candidate (faces containing `k` add zero, as they
    // should), one dot product each instead of a sum over the fan.
    scratch.candidates.clear();
    for &k in &scratch.neighbors {
        if on_boundary && k != fan_start && k != fan_end {
            continue;
        }
        if along.is_some_and(|along| !along.contains(&k)) {
            continue;
        }
        let cone = -area.dot(p(k) - xv);
        scratch.candidates.push((cone.abs(), k, cone));
    }

    // Candidates in increasing (|cone|, M0 id): the first is nearly always valid, so take the
    // least one at a time instead of sorting them.
    let valence = scratch.neighbors.len();
    'candidate: while let Some(best) = (0..scratch.candidates.len()).min_by(|&x, &y| {
        let (x, y) = (&scratch.candidates[x], &scratch.candidates[y]);
        x.0.total_cmp(&y.0)
            .then_with(|| m0_id[x.1 as usize].cmp(&m0_id[y.1 as usize]))
    }) {
        let (_, k, cone) = scratch.candidates.swap_remove(best);
        let xk = p(k) - xv;
        // No surviving face may flip or degenerate.
        let mut opposite = [NEVER; 2];
        scratch.after.clear();
        for ((&[a, b], &[xa, xb]), &old) in fan.iter().zip(&scratch.positions).zip(&scratch.normals)
        {
            if a == k {
                opposite[0] = b;
                continue;
            }
            if b == k {
                opposite[1] = a;
                continue;
            }
            let new = (xa - xk).cross(xb - xk);
            if old.dot(new) <= 0.0 {
                continue 'candidate;
            }
            scratch.after.push(([a, b], new));
        }
        if !view.m0_normals.is_empty()
            && turns_against_m0(v, k, &scratch.after, &mut scratch.ring, view)
        {
            continue;
        }
        // Link condition: apart from the opposite vertices, no neighbour of v may be one of k.
        let neighbors = &scratch.neighbors;
        // (Without early exits: this runs for every face of `k`, and exits would be unpredictable.)
        let shared = |x: u32| {
            let found = neighbors.iter().fold(false, |found, &y| found | (y == x));
            found & (x != opposite[0]) & (x != opposite[1])
        };
        let mut link_ok = true;
        let tetrahedron_check = !on_boundary && valence == 3;
        let single_triangle = on_boundary && valence == 2;
        let third = if opposite[0] != NEVER {
            opposite[0]
        } else {
            opposite[1]
        };
        let mut faces_on_third_edge = 0;
        view.for_each_face_of(k, |a, b| {
            link_ok &= !(shared(a) | shared(b));
            // The tetrahedron case: k's other faces already hold both opposite vertices.
            if tetrahedron_check
                && (a == opposite[0] && b == opposite[1] || a == opposite[1] && b == opposite[0])
            {
                link_ok = false;
            }
            if single_triangle && (a == third || b == third) {
                faces_on_third_edge += 1;
            }
        });
        if !link_ok || (single_triangle && faces_on_third_edge < 2) {
            continue;
        }
        return Some((k, cone));
    }
    None
}

/// Whether one of the faces `(k, a, b)` a collapse `v -> k` leaves (`after`, with their
/// normals) turns against M0, its normal pointing away from the sum of M0's vertex normals at
/// its three corners, or folds over a neighbour (normals more than 150° apart): across `k-a` and
/// `k-b`, another face of `after` or one of `k`'s own; across `a-b`, the face there, which the
/// collapse does not change. The orientation test, which is cheap, goes first for every face.
fn turns_against_m0(
    v: u32,
    k: u32,
    after: &[([u32; 2], DVec3)],
    ring: &mut Vec<([u32; 2], DVec3)>,
    view: &PassView,
) -> bool {
    let m0 = |c: u32| {
        let n = view.m0_normals[view.vertex_id[c as usize] as usize];
        DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64)
    };
    let p = |c: u32| point(view.points, c);
    let (xk, at_k) = (p(k), m0(k));
    if after
        .iter()
        .any(|&([a, b], new)| new.dot(at_k + m0(a) + m0(b)) <= 0.0)
    {
        return true;
    }
    // cos 150°: two faces whose unit normals' dot product is below this fold over each other.
    const FOLD_COS: f64 = -0.866_025_403_784_438_6;
    let folds = |x: DVec3, y: DVec3| x.dot(y) < FOLD_COS * x.length() * y.length();
    // k's one-ring after the collapse: `after`, and k's own faces but those with `v`, which go.
    ring.clear();
    ring.extend_from_slice(after);
    view.for_each_face_of(k, |x, y| {
        if x != v && y != v {
            ring.push(([x, y], (p(x) - xk).cross(p(y) - xk)));
        }
    });
    after.iter().any(|&([a, b], new)| {
        // Across k-a a face (k, x, a), across k-b a face (k, b, y).
        if ring
            .iter()
            .any(|&([x, y], normal)| (y == a || x == b) && folds(new, normal))
        {
            return true;
        }
        // The face across a-b is (a, c, b) as a face of `a`.
        let mut across = NEVER;
        view.for_each_face_of(a, |x, y| {
            if y == b {
                across = x;
            }
        });
        across != NEVER && {
            let xa = p(a);
            folds(new, (p(across) - xa).cross(p(b) - xa))
        }
    })
}
