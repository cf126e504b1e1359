//! Texture coordinates that follow their vertices' slide along the surface, for the write-backs
//! (and, through [`crate::io::scene::Scene::follow_slide`] and `carry::follow_slide`, for what is
//! carried into another format).
//!
//! Not from the paper: the default fairing's tangential relaxation (and the normal-projected
//! iteration, a little) moves vertices *along* the surface, and a texture coordinate that stays
//! with its vertex drags the texture with it (about a third of an edge length RMS on a noisy
//! scan). Writing a file back, each texture coordinate of a moved vertex is therefore moved to
//! what the texture holds where the vertex slid to, so that the texture stays where it was.
//!
//! How it reads the move. The vertex's displacement d = x' − x is split along the unit normal n
//! of its faces *after* the move: the part along n is the smoothing proper (the surface came
//! closer to where it should be: the texture point there is the same), the rest, d_t, is the
//! slide. The slide's end x + d_t is located on the faces as they were before the move, all
//! seen in the plane normal to n: starting from the face around the vertex (among those that use
//! this texture coordinate: on a UV seam a vertex has one per side) that holds it best, and
//! stepping, while it lies outside the face, across the edge it lies beyond to the face on the
//! other side that continues the same texture chart (the same texture coordinates at the edge's
//! two ends), a few faces at most. The face that holds it gives the texture coordinate by its
//! barycentric coordinates. A slide that crosses a seam takes the last face's texture map on past
//! it (a chart's texture continues beyond its seam, and the other side's coordinate follows in
//! its own chart); one that leaves the surface (off a boundary) or goes too far stops at the
//! nearest point of the last face reached. Working in the tangent plane of
//! the result keeps the input's noise out: the noisy faces' tilt only shortens their projected
//! edges a little, where projecting the new position on the noisy faces would read the noise
//! itself as a slide.
//!
//! A texture coordinate several vertices share cannot follow them all: it is left as it is and
//! counted, so that the caller can say so.

use glam::DVec3;
use rayon::prelude::*;

/// Faces a slide may cross before it stops.
const MAX_STEPS: usize = 12;

/// A triangle of a file as the write-backs see it: per corner, the file's vertex and its texture
/// coordinate ([`NO_UV`]: the corner has none). 24 bytes a triangle, where
/// `(usize, Option<usize>)` corners would take 72: the tables of a big file stay small.
pub(crate) type UvTriangle = [[u32; 2]; 3];

/// A corner without a texture coordinate.
pub(crate) const NO_UV: u32 = u32::MAX;

/// What [`follow`] gives: the new value of every texture coordinate that moves.
#[derive(Debug, Default)]
pub(crate) struct FollowedUvs {
    /// `moved[t]`: the new (u, v) of texture coordinate `t`, `None` where it stays.
    pub moved: Vec<Option<[f64; 2]>>,
    /// Texture coordinates left as they were because several moved vertices share them.
    pub shared: usize,
}

/// The texture coordinates `uvs` of the triangles `triangles` (over the file's vertices, whose
/// positions are `before` and `after` the move), moved to follow the vertices' slide along the
/// surface (see the module docs): the wedges and edges are tabled once, then each texture
/// coordinate of a moved vertex walks on its own, in parallel.
pub(crate) fn follow(
    before: &[[f32; 3]],
    after: &[[f32; 3]],
    triangles: &[UvTriangle],
    uvs: &[[f64; 2]],
) -> FollowedUvs {
    // Indices past what the u32 corners and edge entries hold: nothing follows (a file that
    // size does not fit in memory anyway).
    if uvs.len() >= NO_UV as usize
        || before.len() >= (u32::MAX - 1) as usize
        || triangles.len() >= (u32::MAX / 3) as usize
    {
        return FollowedUvs {
            moved: vec![None; uvs.len()],
            shared: 0,
        };
    }
    let wedges = Wedges::build(before, after, triangles, uvs.len());
    let edges = sorted_edges(triangles);
    let surface = Surface {
        before,
        after,
        triangles,
        uvs,
        normals: &wedges.normals,
        edges: &edges,
    };
    let moved_uvs: Vec<Option<[f64; 2]>> = (0..uvs.len())
        .into_par_iter()
        .with_min_len(1024)
        .map(|t| {
            let v = wedges.owner[t];
            let wedge = wedges.faces(t);
            if v >= SHARED || wedge.is_empty() {
                return None;
            }
            surface.follow_one(v, wedge)
        })
        .collect();
    let shared = (0..uvs.len())
        .filter(|&t| wedges.owner[t] == SHARED && !wedges.faces(t).is_empty())
        .count();
    FollowedUvs {
        moved: moved_uvs,
        shared,
    }
}

/// Why [`follow_texture_coordinates`] refused its arrays.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TextureFollowError {
    /// `before` and `after` hold different numbers of vertices.
    #[error("the positions before ({before}) and after ({after}) the move differ in count")]
    VertexCounts { before: usize, after: usize },
    /// The vertex triangles and the texture triangles differ in count.
    #[error("{triangles} triangles but {texture_triangles} triangles of texture coordinates")]
    TriangleCounts {
        triangles: usize,
        texture_triangles: usize,
    },
    /// A corner names a vertex beyond the positions.
    #[error("triangle {triangle} names vertex {vertex}, but there are {count} vertices")]
    VertexBeyond {
        triangle: usize,
        vertex: u32,
        count: usize,
    },
    /// A corner names a texture coordinate beyond the table.
    #[error("triangle {triangle} names texture coordinate {coordinate}, but there are {count}")]
    CoordinateBeyond {
        triangle: usize,
        coordinate: u32,
        count: usize,
    },
    /// A texture coordinate or a position is NaN or infinite.
    #[error("{what} {index} is not finite")]
    NotFinite { what: &'static str, index: usize },
}

/// What [`follow_texture_coordinates`] gives.
#[derive(Debug, Clone, PartialEq)]
pub struct FollowedTexture {
    /// Every texture coordinate: moved where its vertex slid, else as it was.
    pub uvs: Vec<[f64; 2]>,
    /// Texture coordinates left as they were because several moved vertices share them.
    pub shared: usize,
}

/// Texture coordinates that follow their vertices' slide along the surface (see the module
/// docs), for a front end that holds its own texture coordinates (the Python package, and
/// through it an add-on): `triangles` over the vertices, moved from `before` to `after`;
/// `texture_triangles[t][k]`, the index in `uvs` of corner `k` of triangle `t`. Arrays that do
/// not fit together are refused, naming the first thing wrong.
pub fn follow_texture_coordinates(
    before: &[[f32; 3]],
    after: &[[f32; 3]],
    triangles: &[[u32; 3]],
    texture_triangles: &[[u32; 3]],
    uvs: &[[f64; 2]],
) -> Result<FollowedTexture, TextureFollowError> {
    if before.len() != after.len() {
        return Err(TextureFollowError::VertexCounts {
            before: before.len(),
            after: after.len(),
        });
    }
    if triangles.len() != texture_triangles.len() {
        return Err(TextureFollowError::TriangleCounts {
            triangles: triangles.len(),
            texture_triangles: texture_triangles.len(),
        });
    }
    for (what, points) in [("position before", before), ("position after", after)] {
        if let Some(index) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(TextureFollowError::NotFinite { what, index });
        }
    }
    if let Some(index) = uvs.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(TextureFollowError::NotFinite {
            what: "texture coordinate",
            index,
        });
    }
    let mut corners: Vec<UvTriangle> = Vec::with_capacity(triangles.len());
    for (triangle, (vertices, coordinates)) in triangles.iter().zip(texture_triangles).enumerate() {
        let mut corner = [[0u32; 2]; 3];
        for k in 0..3 {
            let (vertex, coordinate) = (vertices[k], coordinates[k]);
            if vertex as usize >= before.len() {
                return Err(TextureFollowError::VertexBeyond {
                    triangle,
                    vertex,
                    count: before.len(),
                });
            }
            if coordinate as usize >= uvs.len() {
                return Err(TextureFollowError::CoordinateBeyond {
                    triangle,
                    coordinate,
                    count: uvs.len(),
                });
            }
            corner[k] = [vertex, coordinate];
        }
        corners.push(corner);
    }
    let followed = follow(before, after, &corners, uvs);
    let moved = uvs
        .iter()
        .zip(followed.moved)
        .map(|(&old, new)| new.unwrap_or(old))
        .collect();
    Ok(FollowedTexture {
        uvs: moved,
        shared: followed.shared,
    })
}

/// A texture coordinate's vertex not seen yet.
const NONE: u32 = u32::MAX;
/// A texture coordinate several vertices use.
const SHARED: u32 = u32::MAX - 1;

/// Vertex `v` of `points` in f64.
fn point(points: &[[f32; 3]], v: u32) -> DVec3 {
    DVec3::from(points[v as usize].map(f64::from))
}

/// Per vertex its area normal after the move; per texture coordinate its vertex ([`NONE`],
/// [`SHARED`]) and its wedge: the faces that use it at a moved vertex.
struct Wedges {
    normals: Vec<DVec3>,
    owner: Vec<u32>,
    /// `faces[starts[t]..starts[t + 1]]`: texture coordinate `t`'s wedge.
    starts: Vec<u32>,
    faces: Vec<u32>,
}

impl Wedges {
    fn build(
        before: &[[f32; 3]],
        after: &[[f32; 3]],
        triangles: &[UvTriangle],
        uv_count: usize,
    ) -> Wedges {
        let moved = |v: u32| before[v as usize] != after[v as usize];
        // Every vertex's area normal after the move (summed over all its faces).
        let mut normals = vec![DVec3::ZERO; before.len()];
        let mut owner = vec![NONE; uv_count];
        // How many faces use each texture coordinate at a moved vertex (its wedge; empty where
        // no vertex using it moved).
        let mut wedge_sizes = vec![0u32; uv_count + 1];
        for triangle in triangles {
            let [a, b, c] = triangle.map(|[v, _]| point(after, v));
            let area = (b - a).cross(c - a);
            for &[v, t] in triangle {
                normals[v as usize] += area;
                if t == NO_UV {
                    continue;
                }
                let t = t as usize;
                owner[t] = match owner[t] {
                    NONE => v,
                    o if o == v => o,
                    _ => SHARED,
                };
                wedge_sizes[t + 1] += u32::from(moved(v));
            }
        }
        // The wedges, side by side: faces[wedge_sizes[t]..wedge_sizes[t + 1]] after the sums.
        for t in 0..uv_count {
            wedge_sizes[t + 1] += wedge_sizes[t];
        }
        let starts = wedge_sizes;
        let mut fill = starts.clone();
        let mut faces = vec![0u32; starts[uv_count] as usize];
        for (f, triangle) in triangles.iter().enumerate() {
            for &[v, t] in triangle {
                if t != NO_UV && moved(v) {
                    faces[fill[t as usize] as usize] = f as u32;
                    fill[t as usize] += 1;
                }
            }
        }
        Wedges {
            normals,
            owner,
            starts,
            faces,
        }
    }

    /// Texture coordinate `t`'s wedge.
    fn faces(&self, t: usize) -> &[u32] {
        &self.faces[self.starts[t] as usize..self.starts[t + 1] as usize]
    }
}

/// Every edge of every face by its ends (lower vertex first) and the corner it starts from
/// (3 f + k), sorted: the faces across an edge are those with the same ends, and of those the
/// ones whose ends carry the same texture coordinates ([`edge_key`]) are in the same chart;
/// another is a face of another chart (a seam). 12 bytes an edge side.
fn sorted_edges(triangles: &[UvTriangle]) -> Vec<[u32; 3]> {
    let mut edges: Vec<[u32; 3]> = triangles
        .par_iter()
        .enumerate()
        .flat_map_iter(|(f, triangle)| {
            (0..3).map(move |k| {
                let key = edge_key(triangle, k);
                [key[0], key[1], 3 * f as u32 + k as u32]
            })
        })
        .collect();
    edges.par_sort_unstable();
    edges
}

/// The surface the texture coordinates walk on: the positions before and after, the faces with
/// their texture coordinates, the vertices' normals after and the sorted edges.
struct Surface<'a> {
    before: &'a [[f32; 3]],
    after: &'a [[f32; 3]],
    triangles: &'a [UvTriangle],
    uvs: &'a [[f64; 2]],
    normals: &'a [DVec3],
    edges: &'a [[u32; 3]],
}

impl Surface<'_> {
    /// The faces on the edge `key` (from `edge_key`): each with its own key of that edge.
    fn faces_on(&self, key: [u32; 4]) -> impl Iterator<Item = ([u32; 4], u32)> + '_ {
        let edges = self.edges;
        let first = edges.partition_point(|e| [e[0], e[1]] < [key[0], key[1]]);
        edges[first..]
            .iter()
            .take_while(move |e| [e[0], e[1]] == [key[0], key[1]])
            .map(|e| {
                let (g, k) = (e[2] / 3, e[2] % 3);
                (edge_key(&self.triangles[g as usize], k as usize), g)
            })
    }

    /// Where the texture coordinate of vertex `v` on the faces `wedge` moves: the slide's end
    /// located by walking across the faces (see the module docs); `None` where it stays.
    fn follow_one(&self, v: u32, wedge: &[u32]) -> Option<[f64; 2]> {
        let n = self.normals[v as usize].try_normalize()?;
        let tangential = |d: DVec3| d - d.dot(n) * n;
        let x = point(self.before, v);
        let target = tangential(point(self.after, v) - x);
        // The barycentric coordinates of the slide's end in face f seen in the plane (`None`
        // for a face seen nearly edge-on there).
        let projected =
            |f: u32| self.triangles[f as usize].map(|[u, _]| tangential(point(self.before, u) - x));
        let barycentric = |f: u32| -> Option<[f64; 3]> {
            let p = projected(f);
            let area = |a: DVec3, b: DVec3, c: DVec3| (b - a).cross(c - a).dot(n);
            let whole = area(p[0], p[1], p[2]);
            let scale = (p[1] - p[0]).length() * (p[2] - p[0]).length();
            // (NaN fails the comparison too.)
            if whole.abs().partial_cmp(&(MIN_SINE * scale)) != Some(std::cmp::Ordering::Greater) {
                return None;
            }
            Some([
                area(target, p[1], p[2]) / whole,
                area(p[0], target, p[2]) / whole,
                area(p[0], p[1], target) / whole,
            ])
        };
        let least = |l: &[f64; 3]| l[0].min(l[1]).min(l[2]);
        // The wedge's face that holds the end best.
        let (mut face, mut weights) = wedge
            .iter()
            .filter_map(|&f| barycentric(f).map(|l| (f, l)))
            .max_by(|a, b| least(&a.1).total_cmp(&least(&b.1)))?;
        let mut previous = u32::MAX;
        // Where the walk stops outside its face: across a seam the face's texture map goes on
        // (a chart's texture continues past its seam), elsewhere (a boundary, too far, a fold)
        // the nearest point of the face.
        let mut extend = false;
        for _ in 0..MAX_STEPS {
            if least(&weights) >= -1e-9 {
                break;
            }
            // Across the edge opposite the most negative weight, to the chart's face beyond.
            let k = (0..3)
                .min_by(|&i, &j| weights[i].total_cmp(&weights[j]))
                .unwrap_or(0);
            let triangle = &self.triangles[face as usize];
            let key = edge_key(triangle, (k + 1) % 3);
            // (An edge with a corner without a coordinate belongs to no chart.)
            let charted = key[2] != NO_UV && key[3] != NO_UV;
            let across = self
                .faces_on(key)
                .find(|&(other, g)| charted && other == key && g != face);
            let Some((_, next)) = across else {
                // No face of this chart beyond: a seam if another chart's face is there.
                extend = self.faces_on(key).any(|(other, _)| other != key);
                break;
            };
            let Some(l) = barycentric(next).filter(|_| next != previous) else {
                break;
            };
            (previous, face, weights) = (face, next, l);
        }
        // Past a seam by at most about a face: the face's map goes on; else its nearest point.
        let weights = if extend && least(&weights) >= -1.0 || least(&weights) >= 0.0 {
            weights
        } else {
            nearest_on_boundary(projected(face), target)
        };
        let total: f64 = weights.iter().sum();
        if total.is_nan() || total <= 0.0 {
            return None;
        }
        let corners = self.triangles[face as usize];
        let mut uv = [0.0; 2];
        // A face with a corner without a coordinate gives none.
        if corners.iter().any(|&[_, c]| c == NO_UV) {
            return None;
        }
        for (w, [_, c]) in weights.iter().zip(corners) {
            for (out, value) in uv.iter_mut().zip(self.uvs[c as usize]) {
                *out += w / total * value;
            }
        }
        uv.iter().all(|c| c.is_finite()).then_some(uv)
    }
}

/// The least sine of the angle between a face's edges, seen in the tangent plane, for the face
/// to locate a point (a face seen nearly edge-on, a fold of the noise, is passed over).
const MIN_SINE: f64 = 0.01;

/// The barycentric weights of the point of triangle `p`'s edges nearest to `q` (a point outside
/// the triangle, all in one plane).
fn nearest_on_boundary(p: [DVec3; 3], q: DVec3) -> [f64; 3] {
    let mut best = (f64::INFINITY, [1.0, 0.0, 0.0]);
    for k in 0..3 {
        let (a, b) = (p[k], p[(k + 1) % 3]);
        let along = b - a;
        let t = ((q - a).dot(along) / along.length_squared()).clamp(0.0, 1.0);
        let t = if t.is_finite() { t } else { 0.0 };
        let distance = (a + t * along - q).length_squared();
        if distance < best.0 {
            let mut weights = [0.0; 3];
            weights[k] = 1.0 - t;
            weights[(k + 1) % 3] = t;
            best = (distance, weights);
        }
    }
    best.1
}

/// The edge from corner `k` of `triangle` to the next corner: both ends' vertices and texture
/// coordinates ([`NO_UV`] for none), the lower vertex first.
fn edge_key(triangle: &UvTriangle, k: usize) -> [u32; 4] {
    let [a, ta] = triangle[k];
    let [b, tb] = triangle[(k + 1) % 3];
    if a <= b {
        [a, b, ta, tb]
    } else {
        [b, a, tb, ta]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat n×n grid of points (z = 0), its triangles with one texture coordinate per vertex
    /// (u, v) = A (x, y) + c, an affine map.
    fn grid(n: usize) -> (Vec<[f32; 3]>, Vec<UvTriangle>, Vec<[f64; 2]>) {
        let mut points = Vec::new();
        let mut uvs = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (x, y) = (i as f32, j as f32);
                points.push([x, y, 0.0]);
                uvs.push(affine(x as f64, y as f64));
            }
        }
        let mut triangles = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let v = j * n + i;
                let c = |v: usize| [v as u32, v as u32];
                triangles.push([c(v), c(v + 1), c(v + n + 1)]);
                triangles.push([c(v), c(v + n + 1), c(v + n)]);
            }
        }
        (points, triangles, uvs)
    }

    fn affine(x: f64, y: f64) -> [f64; 2] {
        [0.1 + 0.05 * x - 0.02 * y, 0.3 + 0.01 * x + 0.04 * y]
    }

    /// On a flat, affinely textured grid, an interior vertex slid in the plane gets the texture
    /// coordinate the texture has at its new place, whatever the direction (every sector); a move
    /// along the normal alone leaves it; a vertex that did not move is not touched.
    #[test]
    fn a_slide_in_the_plane_takes_the_texture_of_the_new_place_and_a_normal_move_none() {
        let (before, triangles, uvs) = grid(5);
        let centre = 12;
        for k in 0..16 {
            let angle = k as f32 * std::f32::consts::TAU / 16.0;
            let (dx, dy) = (0.37 * angle.cos(), 0.37 * angle.sin());
            let mut after = before.clone();
            after[centre] = [2.0 + dx, 2.0 + dy, 0.0];
            let followed = follow(&before, &after, &triangles, &uvs);
            let expected = affine(2.0 + dx as f64, 2.0 + dy as f64);
            let got = followed.moved[centre].expect("the slid vertex's coordinate moves");
            assert!(
                (got[0] - expected[0]).abs() < 1e-7 && (got[1] - expected[1]).abs() < 1e-7,
                "direction {k}: {got:?} instead of {expected:?}"
            );
            assert!(followed
                .moved
                .iter()
                .enumerate()
                .all(|(t, m)| t == centre || m.is_none()));
            assert_eq!(followed.shared, 0);
        }
        let mut lifted = before.clone();
        lifted[centre][2] = 0.3;
        let followed = follow(&before, &lifted, &triangles, &uvs);
        let got = followed.moved[centre].unwrap();
        assert!((got[0] - uvs[centre][0]).abs() < 1e-12 && (got[1] - uvs[centre][1]).abs() < 1e-12);
    }

    /// A slide that leaves the surface over its boundary stops on it, at the boundary's point
    /// nearest to where it went.
    #[test]
    fn a_slide_off_the_boundary_stops_on_it() {
        let (before, triangles, uvs) = grid(5);
        let edge = 2; // (2, 0), on the lower boundary
        let mut after = before.clone();
        after[edge] = [2.2, -0.3, 0.0];
        let got = follow(&before, &after, &triangles, &uvs).moved[edge].unwrap();
        // Back from (u, v) to (x, y) through the affine map.
        let (a, b, c, d) = (0.05, -0.02, 0.01, 0.04);
        let (u, v) = (got[0] - 0.1, got[1] - 0.3);
        let det = a * d - b * c;
        let (x, y) = ((d * u - b * v) / det, (a * v - c * u) / det);
        // The boundary's point nearest to (2.2, −0.3) is (2.2, 0) (positions are f32).
        assert!(y.abs() < 1e-9, "off the boundary line: ({x}, {y})");
        assert!((x - 2.2).abs() < 1e-6, "({x}, {y}) instead of (2.2, 0)");
    }

    /// A slide longer than an edge crosses faces and still lands on the texture of its new
    /// place.
    #[test]
    fn a_long_slide_walks_across_faces() {
        let (before, triangles, uvs) = grid(7);
        let centre = 3 * 7 + 3;
        let mut after = before.clone();
        after[centre] = [4.7, 1.6, 0.0];
        let got = follow(&before, &after, &triangles, &uvs).moved[centre].unwrap();
        let expected = affine(4.7, 1.6);
        assert!((got[0] - expected[0]).abs() < 1e-7 && (got[1] - expected[1]).abs() < 1e-7);
    }

    /// A vertex on a seam has a texture coordinate per side; each follows the slide in its own
    /// chart (here the right half's texture is the left's shifted by 0.5 in u), and a
    /// coordinate two moved vertices share stays and is counted.
    #[test]
    fn each_side_of_a_seam_follows_in_its_own_chart_and_shared_coordinates_stay() {
        let (before, mut triangles, mut uvs) = grid(5);
        // Column i = 2 is the seam: faces right of it (x > 2) use copies shifted in u.
        let mut copy = vec![None; before.len()];
        for triangle in &mut triangles {
            let right = triangle.iter().any(|&[v, _]| before[v as usize][0] > 2.0);
            if !right {
                continue;
            }
            for corner in triangle.iter_mut() {
                let v = corner[0] as usize;
                if before[v][0] == 2.0 {
                    let t = *copy[v].get_or_insert_with(|| {
                        let [u, w] = uvs[v];
                        uvs.push([u + 0.5, w]);
                        uvs.len() - 1
                    });
                    corner[1] = t as u32;
                } else {
                    let [u, w] = uvs[v];
                    corner[1] = uvs.len() as u32;
                    uvs.push([u + 0.5, w]);
                }
            }
        }
        let centre = 12; // (2, 2), on the seam
        let mut after = before.clone();
        after[centre] = [2.25, 2.1, 0.0];
        let followed = follow(&before, &after, &triangles, &uvs);
        let left = followed.moved[centre].unwrap();
        let right = followed.moved[copy[centre].unwrap()].unwrap();
        let expected = affine(2.25, 2.1);
        assert!((left[0] - expected[0]).abs() < 1e-7 && (left[1] - expected[1]).abs() < 1e-7);
        assert!(
            (right[0] - expected[0] - 0.5).abs() < 1e-7 && (right[1] - expected[1]).abs() < 1e-7
        );

        // Two vertices using one texture coordinate: it stays, counted once.
        for triangle in &mut triangles {
            for corner in triangle.iter_mut() {
                if corner[0] == 13 {
                    corner[1] = copy[centre].unwrap() as u32;
                }
            }
        }
        let followed = follow(&before, &after, &triangles, &uvs);
        assert_eq!(followed.moved[copy[centre].unwrap()], None);
        assert_eq!(followed.shared, 1);
    }

    #[test]
    fn the_public_entry_point_moves_what_follow_moves_and_refuses_what_does_not_fit() {
        let (before, corners, uvs) = grid(5);
        let triangles: Vec<[u32; 3]> = corners.iter().map(|t| t.map(|c| c[0])).collect();
        let texture: Vec<[u32; 3]> = corners.iter().map(|t| t.map(|c| c[1])).collect();
        let mut after = before.clone();
        after[12] = [2.2, 1.9, 0.0];
        let followed =
            follow_texture_coordinates(&before, &after, &triangles, &texture, &uvs).unwrap();
        let expected = affine(2.2, 1.9);
        assert!((followed.uvs[12][0] - expected[0]).abs() < 1e-6);
        assert!((followed.uvs[12][1] - expected[1]).abs() < 1e-6);
        assert_eq!(followed.uvs[11], uvs[11]);
        assert_eq!(followed.shared, 0);
        let mut beyond = texture.clone();
        beyond[3][1] = uvs.len() as u32;
        assert!(matches!(
            follow_texture_coordinates(&before, &after, &triangles, &beyond, &uvs),
            Err(TextureFollowError::CoordinateBeyond { triangle: 3, .. })
        ));
        assert!(matches!(
            follow_texture_coordinates(&before, &after[1..], &triangles, &texture, &uvs),
            Err(TextureFollowError::VertexCounts { .. })
        ));
        let mut nan = uvs.clone();
        nan[2][0] = f64::NAN;
        assert!(matches!(
            follow_texture_coordinates(&before, &after, &triangles, &texture, &nan),
            Err(TextureFollowError::NotFinite { index: 2, .. })
        ));
    }
}
