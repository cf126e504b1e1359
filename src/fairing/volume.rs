//! Keeping each part's volume over many rounds of constrained fairing (the default's volume
//! correction, [`super::FairOptions::keep_volume`]).
//!
//! Not in the paper. One round of the paper's fairing keeps every triangle's barycentre near its
//! anchor, so it changes the volume little; but the default runs several rounds, each re-anchored
//! where the last one ended, and on coarsely sampled or thin parts each round loses a little
//! (the elephant of `tests/data` lost 1.1 % over 6 rounds, and it got further from its clean
//! surface round after round). After every round this takes the loss back with one number per
//! connected part: every vertex that may move is offset along its normal by the same distance δ,
//! chosen so that the part encloses the volume it enclosed before fairing (about ΔV / A, the
//! volume's derivative under a uniform normal offset being about the area; exactly, the root of
//! the part's volume as a cubic in δ, see [`VolumeKeeper::restore`]).
//! Being a single number per part, it carries no detail of the noise back, unlike a correction
//! that varies over the surface (a low-passed per-vertex correction keeps too much noise:
//! `docs/measurements.md`).
//!
//! An open part has no inside; its "volume" here is that of the cone from its centroid (taken
//! before fairing) to its surface, which a uniform inward drift of the surface lowers just the
//! same. Vertices that must not move (boundary vertices, crease corners, vertices a mask pins)
//! are left out of both the offset and the derivative.

use crate::mesh::{Topology, TriMesh};
use glam::{DVec3, Vec3A};
use rayon::prelude::*;

/// Faces per block of the sums (a fixed block size keeps the sums the same for any number of
/// threads).
const BLOCK: usize = 4096;

/// Newton steps on each part's volume polynomial, at most (see [`VolumeKeeper::restore`]; a
/// round's offset is a small fraction of an edge length, where two or three steps settle).
const NEWTON_STEPS: usize = 8;

/// Whether a vertex is offset (see [`VolumeKeeper::restore`]).
type MovesFlag<'a> = dyn Fn(usize) -> bool + Sync + 'a;

/// The volume of each connected part of a mesh before fairing, and which vertices may be offset.
#[derive(Clone, Debug)]
pub struct VolumeKeeper {
    /// Connected part of each face.
    face_part: Vec<u32>,
    /// Connected part of each vertex (`Topology::component_of_vertex`).
    vertex_part: Vec<u32>,
    /// Per part: the apex of its cone volume and the volume to keep.
    apex: Vec<DVec3>,
    target: Vec<f64>,
    /// Vertices that may be offset.
    movable: Vec<bool>,
}

impl VolumeKeeper {
    /// Records the volume of each connected part of `mesh`; `fixed[v]` (when given for every
    /// vertex) marks vertices that must not move. Boundary vertices never move.
    pub fn new(mesh: &TriMesh, topology: &Topology, fixed: &[bool]) -> Self {
        let n = mesh.positions.len();
        // The topology's connected components (an isolated vertex is a part of its own, with
        // no face and nothing to move).
        let vertex_part = topology.component_of_vertex.clone();
        let parts = topology.components.len();
        let face_part: Vec<u32> = mesh
            .triangles
            .iter()
            .map(|t| vertex_part[t[0] as usize])
            .collect();
        let mut sum = vec![DVec3::ZERO; parts];
        let mut count = vec![0usize; parts];
        for (v, &p) in vertex_part.iter().enumerate() {
            sum[p as usize] += mesh.point(v as u32);
            count[p as usize] += 1;
        }
        let apex: Vec<DVec3> = sum
            .iter()
            .zip(&count)
            .map(|(s, &c)| *s / c.max(1) as f64)
            .collect();
        let movable = (0..n)
            .map(|v| {
                !topology.faces_of(v as u32).is_empty()
                    && !topology.is_boundary_vertex(v as u32)
                    && !fixed.get(v).copied().unwrap_or(false)
            })
            .collect();
        let mut keeper = VolumeKeeper {
            face_part,
            vertex_part,
            apex,
            target: Vec::new(),
            movable,
        };
        keeper.target = keeper
            .volume_cubics(mesh, None)
            .iter()
            .map(|c| c[0])
            .collect();
        keeper
    }

    /// Number of connected parts.
    pub fn parts(&self) -> usize {
        self.apex.len()
    }

    /// Per part, the coefficients (c0, c1, c2, c3) of its cone volume about its apex (for a
    /// closed part, its enclosed volume) as a cubic in δ when every vertex moves by δ times its
    /// `normals` entry (each face's triple product expanded in δ): c0 is the volume now. `None`:
    /// no normals, only c0 (the other three are zero). One sum for both uses, so that a part that
    /// did not change reads its target exactly and is not offset at all.
    ///
    /// Each face's four coefficients are products of single precision points (relative to the
    /// apex, so the products are of the part's size, not of its distance from the origin) summed
    /// in double precision: a face's rounding, ~1e-7 of its own cone volume, averages out over the
    /// faces (the sum's, not the faces', error counts against the volume change of a round, of
    /// order 1e-5 of the volume). The expansion shares its cross products: a·(b×c),
    /// na·(b×c) + a·(nb×c + b×nc), na·(nb×c + b×nc) + a·(nb×nc), na·(nb×nc); in double precision
    /// and as eight separate triple products this pass took as long as four iterations of the
    /// operator (`docs/measurements.md`, "The volume correction").
    /// `normals` come with which vertices move (the others' normals count as zero).
    fn volume_cubics(
        &self,
        mesh: &TriMesh,
        normals: Option<(&[Vec3A], &MovesFlag<'_>)>,
    ) -> Vec<[f64; 4]> {
        let parts = self.parts();
        let apexes: Vec<Vec3A> = self.apex.iter().map(|a| a.as_vec3a()).collect();
        let point = |v: u32| Vec3A::from_array(mesh.positions[v as usize]);
        let blocks: Vec<Vec<[f64; 4]>> = mesh
            .triangles
            .par_chunks(BLOCK)
            .zip(self.face_part.par_chunks(BLOCK))
            .map(|(faces, owners)| {
                let mut sums = vec![[0.0; 4]; parts];
                for (t, &part) in faces.iter().zip(owners) {
                    let [a, b, c] = t.map(|v| point(v) - apexes[part as usize]);
                    let terms = match normals {
                        None => [a.dot(b.cross(c)), 0.0, 0.0, 0.0],
                        Some((normals, moves)) => {
                            face_cubic([a, b, c], t.map(|v| moving_normal(normals, moves, v)))
                        }
                    };
                    let sum = &mut sums[part as usize];
                    for k in 0..4 {
                        sum[k] += f64::from(terms[k]);
                    }
                }
                sums
            })
            .collect();
        let mut cubic = vec![[0.0f64; 4]; parts];
        for block in blocks {
            for (total, sum) in cubic.iter_mut().zip(block) {
                for k in 0..4 {
                    total[k] += sum[k] / 6.0;
                }
            }
        }
        cubic
    }

    /// Offsets the movable vertices of each part along their normals so that the part's volume
    /// is again what it was when `self` was made; vertices for which `held` is true stay too
    /// (crease corners). `topology` is the mesh's. Returns the largest offset applied.
    ///
    /// With every movable vertex v offset by δ along its unit normal n_v, each face's cone
    /// volume (a·(b×c))/6 about the part's apex is a cubic in δ; one pass over the faces sums the
    /// four coefficients per part, and the part's δ is the root of its cubic nearest zero
    /// (Newton's method from zero, on the polynomial: no pass over the mesh per step). So the
    /// volume is restored exactly (to rounding), where two linearised steps left a remainder of
    /// second order, and the mesh is read four times (face normals, vertex normals, coefficients,
    /// offsets) instead of seven.
    pub fn restore(
        &self,
        mesh: &mut TriMesh,
        topology: &Topology,
        held: impl Fn(usize) -> bool + Sync,
    ) -> f64 {
        self.restore_with_normals(mesh, topology, held).0
    }

    /// [`Self::restore`], also giving back the offsets it applied ([`Offsets`]: every vertex's
    /// unit normal and each part's distance), to read the normals again or to offset another
    /// state of the mesh the same way ([`Self::offset`]).
    pub fn restore_with_normals(
        &self,
        mesh: &mut TriMesh,
        topology: &Topology,
        held: impl Fn(usize) -> bool + Sync,
    ) -> (f64, Offsets) {
        let (largest, offsets, _) = self.restore_parts(mesh, topology, held);
        (largest, offsets)
    }

    /// [`Self::restore_with_normals`], also giving back each part's cubic as it was before the
    /// offsets (about the positions given).
    fn restore_parts(
        &self,
        mesh: &mut TriMesh,
        topology: &Topology,
        held: impl Fn(usize) -> bool + Sync,
    ) -> (f64, Offsets, Vec<[f64; 4]>) {
        let moves = |v: usize| self.movable[v] && !held(v);
        let positions = &mesh.positions;
        let point = |v: u32| Vec3A::from_array(positions[v as usize]);
        // Each vertex's unit normal: the sum of its faces' area normals N_f = (b − a) × (c − a),
        // each computed once (a pass over the faces, then one over the vertices); the offsets
        // take them for the movable vertices and zero for the vertices that stay.
        let face_normals: Vec<Vec3A> = mesh
            .triangles
            .par_iter()
            .with_min_len(BLOCK)
            .map(|t| {
                let [a, b, c] = t.map(point);
                (b - a).cross(c - a)
            })
            .collect();
        let normals: Vec<Vec3A> = (0..positions.len())
            .into_par_iter()
            .with_min_len(BLOCK)
            .map(|v| {
                let sum = topology
                    .faces_of(v as u32)
                    .iter()
                    .fold(Vec3A::ZERO, |sum, &f| sum + face_normals[f as usize]);
                let length = sum.length();
                if length > 0.0 && length.is_finite() {
                    sum / length
                } else {
                    Vec3A::ZERO
                }
            })
            .collect();
        drop(face_normals);
        // Per part, the coefficients of V(δ) = c0 + c1 δ + c2 δ² + c3 δ³.
        let cubic = self.volume_cubics(mesh, Some((&normals, &moves)));
        let offsets = Offsets {
            normals,
            distances: cubic
                .iter()
                .zip(&self.target)
                .map(|(c, &target)| offset_for(c, target))
                .collect(),
        };
        self.offset(&mut mesh.positions, &offsets, held);
        (offsets.largest(), offsets, cubic)
    }

    /// [`Self::restore`], keeping what [`Self::restore_again`] needs to make the correction again
    /// after part of the mesh moved. `held` is given per vertex (missing entries: false).
    pub fn restore_to_redo(&self, mesh: &mut TriMesh, topology: &Topology, held: &[bool]) -> Redo {
        let is_held = |v: usize| held.get(v).copied().unwrap_or(false);
        let (_, offsets, cubic) = self.restore_parts(mesh, topology, is_held);
        let cubic = cubic
            .into_iter()
            .zip(&offsets.distances)
            .map(|(c, &distance)| shifted(c, distance))
            .collect();
        Redo {
            normals: offsets.normals,
            cubic,
            positions: mesh.positions.clone(),
            held: (0..mesh.positions.len()).map(is_held).collect(),
        }
    }

    /// The correction of [`Self::restore_to_redo`] made again on `positions`, the same mesh after
    /// some vertices moved or became `held` (per vertex; missing entries: false): every part's
    /// volume is brought back to its target along the first correction's normals, as the first
    /// correction did, but only the faces around the vertices that changed are read (their terms
    /// of the cubic taken out as they were and put in as they are), not the whole mesh; the
    /// offset itself is one pass over the vertices. The normals are those of the first
    /// correction's state, not recomputed: an offset is a small fraction of an edge length, and
    /// the cubic's root makes the volume exact along whichever normals it is taken.
    pub fn restore_again(
        &self,
        redo: &mut Redo,
        positions: &mut [[f32; 3]],
        topology: &Topology,
        triangles: &[[u32; 3]],
        held: &[bool],
    ) -> f64 {
        let is_held = |v: usize| held.get(v).copied().unwrap_or(false);
        let mut faces: Vec<u32> = (0..positions.len())
            .filter(|&v| positions[v] != redo.positions[v] || is_held(v) != redo.held[v])
            .flat_map(|v| topology.faces_of(v as u32).iter().copied())
            .collect();
        faces.sort_unstable();
        faces.dedup();
        let parts = self.parts();
        let mut change = vec![[0.0f64; 4]; parts];
        let normals = &redo.normals;
        let was_moving = |v: usize| self.movable[v] && !redo.held[v];
        let moves = |v: usize| self.movable[v] && !is_held(v);
        for &f in &faces {
            let part = self.face_part[f as usize] as usize;
            let apex = self.apex[part].as_vec3a();
            let t = triangles[f as usize];
            let terms = |points: &[[f32; 3]], moving: &MovesFlag<'_>| {
                face_cubic(
                    t.map(|v| Vec3A::from_array(points[v as usize]) - apex),
                    t.map(|v| moving_normal(normals, moving, v)),
                )
            };
            let (before, now) = (
                terms(&redo.positions, &was_moving),
                terms(positions, &moves),
            );
            for k in 0..4 {
                change[part][k] += (f64::from(now[k]) - f64::from(before[k])) / 6.0;
            }
        }
        let distances: Vec<f64> = redo
            .cubic
            .iter_mut()
            .zip(&change)
            .zip(&self.target)
            .map(|((c, change), &target)| {
                for k in 0..4 {
                    c[k] += change[k];
                }
                let distance = offset_for(c, target);
                *c = shifted(*c, distance);
                distance
            })
            .collect();
        let offsets = Offsets {
            normals: std::mem::take(&mut redo.normals),
            distances,
        };
        self.offset(positions, &offsets, is_held);
        let largest = offsets.largest();
        redo.normals = offsets.normals;
        redo.positions.copy_from_slice(positions);
        for (v, was) in redo.held.iter_mut().enumerate() {
            *was = is_held(v);
        }
        largest
    }

    /// Moves `positions` (the mesh's, or another state of the same connectivity) by `offsets`:
    /// every movable vertex for which `held` is false by its part's distance along its normal.
    pub fn offset(
        &self,
        positions: &mut [[f32; 3]],
        offsets: &Offsets,
        held: impl Fn(usize) -> bool + Sync,
    ) {
        let moves = |v: usize| self.movable[v] && !held(v);
        let distances = &offsets.distances;
        positions
            .par_iter_mut()
            .zip(&offsets.normals)
            .zip(&self.vertex_part)
            .enumerate()
            .with_min_len(BLOCK)
            .for_each(|(v, ((position, normal), &part))| {
                let offset = distances[part as usize];
                if *normal != Vec3A::ZERO && offset != 0.0 && moves(v) {
                    let moved = DVec3::from(position.map(f64::from)) + normal.as_dvec3() * offset;
                    *position = moved.as_vec3().to_array();
                }
            });
    }
}

/// A face's four terms of [`VolumeKeeper::volume_cubics`] (six times its share of c0..c3): its
/// corners relative to the apex, and their normals (zero for a vertex that does not move).
#[inline]
fn face_cubic([a, b, c]: [Vec3A; 3], [na, nb, nc]: [Vec3A; 3]) -> [f32; 4] {
    let bc = b.cross(c);
    let mixed = nb.cross(c) + b.cross(nc);
    let nbc = nb.cross(nc);
    [
        a.dot(bc),
        na.dot(bc) + a.dot(mixed),
        na.dot(mixed) + a.dot(nbc),
        na.dot(nbc),
    ]
}

/// Vertex `v`'s normal in the cubic: its entry of `normals` where it moves, zero where it stays.
#[inline]
fn moving_normal(normals: &[Vec3A], moves: &MovesFlag<'_>, v: u32) -> Vec3A {
    if moves(v as usize) {
        normals[v as usize]
    } else {
        Vec3A::ZERO
    }
}

/// The cubic `c` of a volume in δ, taken about the state `distance` further along the normals:
/// the coefficients of t in c(distance + t).
fn shifted(c: [f64; 4], distance: f64) -> [f64; 4] {
    let d = distance;
    [
        c[0] + d * (c[1] + d * (c[2] + d * c[3])),
        c[1] + d * (2.0 * c[2] + d * 3.0 * c[3]),
        c[2] + d * 3.0 * c[3],
        c[3],
    ]
}

/// A volume correction kept so that it can be made again after part of the mesh moved
/// ([`VolumeKeeper::restore_to_redo`], [`VolumeKeeper::restore_again`]): the normals of the first
/// correction, each part's volume as a cubic along them about the positions the last correction
/// left, those positions and the vertices it held.
#[derive(Clone, Debug)]
pub struct Redo {
    normals: Vec<Vec3A>,
    cubic: Vec<[f64; 4]>,
    positions: Vec<[f32; 3]>,
    held: Vec<bool>,
}

/// What one volume correction applied ([`VolumeKeeper::restore_with_normals`]).
#[derive(Clone, Debug, Default)]
pub struct Offsets {
    /// Every vertex's unit normal (area-weighted; zero where its faces' normals sum to zero,
    /// and for a vertex with no face) before the offsets: the offsets move the surface by a
    /// small fraction of an edge length, uniformly, so these are the corrected mesh's normals
    /// but for that fraction times its curvature (the risk estimate reads them instead of
    /// another pass over the faces).
    pub normals: Vec<Vec3A>,
    /// Each part's distance along the normals.
    pub distances: Vec<f64>,
}

impl Offsets {
    /// The largest distance applied, in either direction.
    fn largest(&self) -> f64 {
        self.distances.iter().fold(0.0f64, |m, d| m.max(d.abs()))
    }
}

/// The root nearest zero of c0 + c1 δ + c2 δ² + c3 δ³ = `target` (Newton's method from zero;
/// the slope at zero, c1, is about the part's movable area, so the first step is the linearised
/// offset ΔV / A). Zero where the part has no movable area or the steps do not settle.
fn offset_for(c: &[f64; 4], target: f64) -> f64 {
    if !(c[1] > 0.0 && c.iter().all(|x| x.is_finite())) {
        return 0.0;
    }
    let mut delta = 0.0f64;
    for _ in 0..NEWTON_STEPS {
        let value = c[0] + delta * (c[1] + delta * (c[2] + delta * c[3])) - target;
        let slope = c[1] + delta * (2.0 * c[2] + delta * 3.0 * c[3]);
        // A slope that is not positive (or NaN) has no root to step to.
        if slope.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            break;
        }
        let step = value / slope;
        delta -= step;
        if step.abs() <= 1e-12 * delta.abs().max(f64::MIN_POSITIVE) {
            break;
        }
    }
    if delta.is_finite() {
        delta
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::metrics::signed_volume;

    #[test]
    fn a_shrunk_part_gets_its_volume_back_and_a_second_part_keeps_its_own() {
        let cube = shapes::cuboid([1.0, 1.0, 1.0], 0.1);
        // Two cubes, the second moved away: two parts.
        let mut mesh = cube.clone();
        let offset = cube.positions.len() as u32;
        mesh.positions
            .extend(cube.positions.iter().map(|p| [p[0] + 3.0, p[1], p[2]]));
        mesh.triangles
            .extend(cube.triangles.iter().map(|t| t.map(|v| v + offset)));
        let topology = Topology::build(&mesh);
        let keeper = VolumeKeeper::new(&mesh, &topology, &[]);
        assert_eq!(keeper.parts(), 2);
        let before = signed_volume(&mesh);
        // Shrink the first cube only, by 1 % about its centre (3 % of its volume: more than a
        // round of fairing loses, 0.2 % at most in the measurements).
        for p in &mut mesh.positions[..offset as usize] {
            *p = p.map(|c| 0.5 + (c - 0.5) * 0.99);
        }
        let second: Vec<[f32; 3]> = mesh.positions[offset as usize..].to_vec();
        keeper.restore(&mut mesh, &topology, |_| false);
        let after = signed_volume(&mesh);
        // The cubic's root: exact but for rounding to f32 positions (a linearised step would
        // leave ~1e-4 here, the offset's second order).
        assert!(
            ((after - before) / before).abs() < 1e-6,
            "volume {after} after restoring, {before} before"
        );
        // The second cube did not change, so it did not move.
        assert_eq!(&mesh.positions[offset as usize..], &second[..]);
    }

    #[test]
    fn a_correction_made_again_after_a_dent_gives_the_volume_back_and_holds_what_it_is_told() {
        let mut mesh = shapes::cuboid([1.0, 1.0, 1.0], 0.1);
        let topology = Topology::build(&mesh);
        let keeper = VolumeKeeper::new(&mesh, &topology, &[]);
        let before = signed_volume(&mesh);
        let relative = |mesh: &TriMesh| ((signed_volume(mesh) - before) / before).abs();
        for p in &mut mesh.positions {
            *p = p.map(|c| 0.5 + (c - 0.5) * 0.99);
        }
        let mut redo = keeper.restore_to_redo(&mut mesh, &topology, &[]);
        assert!(relative(&mesh) < 1e-6, "{}", relative(&mesh));
        // A dent: the vertices of the top face pressed in by a tenth (3 % of the volume, far
        // more than what the unfolding moves), and a few others held where they are.
        let top: Vec<usize> = (0..mesh.positions.len())
            .filter(|&v| mesh.positions[v][2] > 0.99)
            .collect();
        assert!(top.len() > 10, "{}", top.len());
        for &v in &top {
            mesh.positions[v][2] -= 0.1;
        }
        assert!(relative(&mesh) > 1e-2);
        let held: Vec<bool> = (0..mesh.positions.len()).map(|v| v % 7 == 0).collect();
        let dented = mesh.positions.clone();
        let triangles = mesh.triangles.clone();
        let distance =
            keeper.restore_again(&mut redo, &mut mesh.positions, &topology, &triangles, &held);
        assert!(distance > 0.0);
        assert!(relative(&mesh) < 1e-6, "{}", relative(&mesh));
        for v in (0..held.len()).filter(|&v| held[v]) {
            assert_eq!(mesh.positions[v], dented[v], "held vertex {v} moved");
        }
        // Made again with nothing changed, it moves nothing.
        let corrected = mesh.positions.clone();
        keeper.restore_again(&mut redo, &mut mesh.positions, &topology, &triangles, &held);
        assert_eq!(mesh.positions, corrected);
    }

    #[test]
    fn fixed_vertices_stay_and_the_others_make_up_the_volume() {
        let mut mesh = shapes::cuboid([1.0, 1.0, 1.0], 0.1);
        let topology = Topology::build(&mesh);
        let fixed: Vec<bool> = (0..mesh.positions.len()).map(|v| v % 3 == 0).collect();
        let keeper = VolumeKeeper::new(&mesh, &topology, &fixed);
        let before = signed_volume(&mesh);
        let original = mesh.positions.clone();
        for p in &mut mesh.positions {
            *p = p.map(|c| 0.5 + (c - 0.5) * 0.98);
        }
        let shrunk = mesh.positions.clone();
        keeper.restore(&mut mesh, &topology, |_| false);
        for v in (0..mesh.positions.len()).filter(|v| fixed[*v]) {
            assert_eq!(mesh.positions[v], shrunk[v], "fixed vertex {v} moved");
        }
        let after = signed_volume(&mesh);
        assert!(
            ((after - before) / before).abs() < 1e-6,
            "{after} vs {before}"
        );
        assert_ne!(mesh.positions, original);
    }
}
