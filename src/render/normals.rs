//! Per-vertex normals for smooth shading: each vertex gets the sum of the normals of the
//! triangles around it, each weighted by its triangle's area (the unnormalised cross product is
//! twice the area long, so summing cross products weights by area), then made unit length.
//!
//! Computed on the CPU whenever the displayed mesh changes (a new mesh or new positions), on the
//! renderer's upload thread for big meshes. Face normals are computed in parallel with rayon
//! when the mesh is big; summing them into the vertices is one serial pass (a parallel scatter
//! would need a vertex-to-face table or one accumulator per thread, both costing more memory
//! than the pass costs time).
//!
//! Never NaN: a degenerate triangle (zero area, or a corner that is not finite) adds nothing,
//! a triangle naming a vertex out of range is skipped, and a vertex with no usable triangle gets
//! the zero vector, which the shader reads as "use the face normal".

use rayon::prelude::*;

/// Below this many triangles one thread is faster than handing work to rayon.
const PARALLEL_TRIANGLES: usize = 50_000;

/// Area-weighted unit vertex normals, one per position; `[0, 0, 0]` for a vertex that no
/// triangle with an area touches.
pub fn vertex_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let face = |t: &[u32; 3]| face_normal(positions, t);
    let faces: Vec<[f32; 3]> = if triangles.len() >= PARALLEL_TRIANGLES {
        triangles.par_iter().map(face).collect()
    } else {
        triangles.iter().map(face).collect()
    };
    let mut sums = vec![[0.0f32; 3]; positions.len()];
    for (t, n) in triangles.iter().zip(&faces) {
        if *n == [0.0; 3] {
            continue;
        }
        for &v in t {
            // face_normal gave zero for triangles with a vertex out of range.
            let sum = &mut sums[v as usize];
            for k in 0..3 {
                sum[k] += n[k];
            }
        }
    }
    let unit = |n: &mut [f32; 3]| *n = normalized(*n);
    if sums.len() >= PARALLEL_TRIANGLES {
        sums.par_iter_mut().for_each(unit);
    } else {
        sums.iter_mut().for_each(unit);
    }
    sums
}

/// The triangle's unnormalised normal (twice its area long), or zero when a corner is out of
/// range or not finite.
fn face_normal(positions: &[[f32; 3]], t: &[u32; 3]) -> [f32; 3] {
    let corner = |v: u32| positions.get(v as usize).copied();
    let (Some(a), Some(b), Some(c)) = (corner(t[0]), corner(t[1]), corner(t[2])) else {
        return [0.0; 3];
    };
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let ac = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        ab[1] * ac[2] - ab[2] * ac[1],
        ab[2] * ac[0] - ab[0] * ac[2],
        ab[0] * ac[1] - ab[1] * ac[0],
    ];
    if n.iter().all(|c| c.is_finite()) {
        n
    } else {
        [0.0; 3]
    }
}

/// `n` at unit length, or zero when it has no direction (zero, tiny or not finite).
fn normalized(n: [f32; 3]) -> [f32; 3] {
    // In f64: a sum of tiny areas can underflow when squared in f32.
    let [x, y, z] = n.map(f64::from);
    let length = (x * x + y * y + z * z).sqrt();
    if length > 0.0 && length.is_finite() {
        [
            (x / length) as f32,
            (y / length) as f32,
            (z / length) as f32,
        ]
    } else {
        [0.0; 3]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f32; 3], b: [f32; 3]) -> bool {
        a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-5)
    }

    /// The unit cube, outward-wound, two triangles per side.
    fn cube() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let positions = (0..8)
            .map(|i| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32])
            .collect();
        let quads = [
            [0, 2, 3, 1], // z = 0, facing -z
            [4, 5, 7, 6], // z = 1, facing +z
            [0, 1, 5, 4], // y = 0, facing -y
            [2, 6, 7, 3], // y = 1, facing +y
            [0, 4, 6, 2], // x = 0, facing -x
            [1, 3, 7, 5], // x = 1, facing +x
        ];
        let triangles = quads
            .iter()
            .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
            .collect();
        (positions, triangles)
    }

    #[test]
    fn a_cube_corner_points_along_the_diagonal() {
        let (positions, triangles) = cube();
        let normals = vertex_normals(&positions, &triangles);
        let s = 1.0 / 3f32.sqrt();
        // Each corner has equal area of its three sides around it (each side's two triangles
        // split the side's area; a corner is in one or both of them).
        assert!(close(normals[7], [s, s, s]), "{:?}", normals[7]);
        assert!(close(normals[0], [-s, -s, -s]), "{:?}", normals[0]);
        for n in &normals {
            let length = n.iter().map(|c| c * c).sum::<f32>().sqrt();
            assert!((length - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn a_flat_plane_has_the_planes_normal_everywhere() {
        let n = 6u32;
        let positions: Vec<[f32; 3]> = (0..=n)
            .flat_map(|y| (0..=n).map(move |x| [x as f32 * 0.3, y as f32 * 0.7, 2.0]))
            .collect();
        let index = |x: u32, y: u32| y * (n + 1) + x;
        let triangles: Vec<[u32; 3]> = (0..n)
            .flat_map(|y| {
                (0..n).flat_map(move |x| {
                    [
                        [index(x, y), index(x + 1, y), index(x + 1, y + 1)],
                        [index(x, y), index(x + 1, y + 1), index(x, y + 1)],
                    ]
                })
            })
            .collect();
        for normal in vertex_normals(&positions, &triangles) {
            assert!(close(normal, [0.0, 0.0, 1.0]), "{normal:?}");
        }
    }

    #[test]
    fn degenerate_and_broken_triangles_give_no_nan() {
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 0.0, 0.0], // on the line through 0 and 1: triangle 0-1-3 has no area
            [f32::NAN, 0.0, 0.0],
            [5.0, 5.0, 5.0],      // used by no triangle
            [f32::MAX, 0.0, 0.0], // with the next: a cross product that overflows
            [0.0, f32::MAX, 0.0],
        ];
        let triangles = vec![
            [0, 1, 2],
            [0, 1, 3],
            [1, 1, 1],
            [0, 4, 2],
            [0, 1, 99],
            [0, 6, 7],
        ];
        let normals = vertex_normals(&positions, &triangles);
        assert_eq!(normals.len(), positions.len());
        assert!(normals.iter().flatten().all(|c| c.is_finite()));
        // Only the good triangle counts: its corners face +z, the rest have no direction.
        for v in [0, 1, 2] {
            assert!(close(normals[v], [0.0, 0.0, 1.0]), "{v}: {:?}", normals[v]);
        }
        for v in [3, 4, 5, 6, 7] {
            assert_eq!(normals[v], [0.0; 3], "{v}");
        }
    }

    #[test]
    fn a_big_mesh_gives_the_same_normals_in_parallel() {
        // A bumpy grid past the parallel threshold, against the serial sum done by hand.
        let n = 200u32;
        let positions: Vec<[f32; 3]> = (0..=n)
            .flat_map(|y| {
                (0..=n).map(move |x| {
                    let (fx, fy) = (x as f32 * 0.1, y as f32 * 0.1);
                    [fx, fy, (fx * 1.3).sin() * (fy * 0.7).cos()]
                })
            })
            .collect();
        let index = |x: u32, y: u32| y * (n + 1) + x;
        let triangles: Vec<[u32; 3]> = (0..n)
            .flat_map(|y| {
                (0..n).flat_map(move |x| {
                    [
                        [index(x, y), index(x + 1, y), index(x + 1, y + 1)],
                        [index(x, y), index(x + 1, y + 1), index(x, y + 1)],
                    ]
                })
            })
            .collect();
        assert!(triangles.len() >= PARALLEL_TRIANGLES);
        let normals = vertex_normals(&positions, &triangles);
        let mut sums = vec![[0.0f32; 3]; positions.len()];
        for t in &triangles {
            let f = face_normal(&positions, t);
            for &v in t {
                for k in 0..3 {
                    sums[v as usize][k] += f[k];
                }
            }
        }
        for (n, s) in normals.iter().zip(sums) {
            assert!(close(*n, normalized(s)));
        }
        // Bumpy: the normals vary, unlike a plane's.
        assert!(normals.iter().any(|n| n[2] < 0.9));
    }
}
