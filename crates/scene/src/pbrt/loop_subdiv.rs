//! Loop subdivision (pbrt-v4's `loopsubdiv` shape): each level splits every triangle in four,
//! moving old vertices by Loop's vertex rule and placing new ones by his edge rule (the
//! boundary rules along edges with other than two faces); after the last level every vertex
//! is moved to its limit position. Shading normals are the limit mesh's area-weighted face
//! normals (pbrt-v4 takes them from the limit surface's tangents; the two agree as the mesh
//! refines).

use glam::DVec3;
use std::collections::HashMap;

/// An edge of the control mesh: its ends, the vertices opposite it, and how many faces share
/// it (two inside the surface, one on its boundary; more where it is not a manifold).
struct Edge {
    ends: [u32; 2],
    opposite: [u32; 2],
    faces: u32,
}

/// The edges of `indices`, in the order the faces first meet them, and each face's three
/// edges (edge k joins corners k and k + 1).
fn edges(indices: &[u32]) -> (Vec<Edge>, Vec<[usize; 3]>) {
    let mut index: HashMap<(u32, u32), usize> = HashMap::new();
    let mut list: Vec<Edge> = Vec::new();
    let mut face_edges = Vec::with_capacity(indices.len() / 3);
    for t in indices.chunks_exact(3) {
        let mut fe = [0; 3];
        for k in 0..3 {
            let (a, b, w) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            let key = (a.min(b), a.max(b));
            let e = *index.entry(key).or_insert_with(|| {
                list.push(Edge {
                    ends: [key.0, key.1],
                    opposite: [w, w],
                    faces: 0,
                });
                list.len() - 1
            });
            let edge = &mut list[e];
            if edge.faces == 1 {
                edge.opposite[1] = w;
            }
            edge.faces += 1;
            fe[k] = e;
        }
        face_edges.push(fe);
    }
    (list, face_edges)
}

/// Each vertex's neighbours and, where it lies on the boundary, its boundary neighbours.
fn neighbours(n: usize, edges: &[Edge]) -> (Vec<Vec<u32>>, Vec<Vec<u32>>) {
    let mut all = vec![Vec::new(); n];
    let mut boundary = vec![Vec::new(); n];
    for e in edges {
        let [a, b] = e.ends;
        all[a as usize].push(b);
        all[b as usize].push(a);
        if e.faces != 2 {
            boundary[a as usize].push(b);
            boundary[b as usize].push(a);
        }
    }
    (all, boundary)
}

fn sum(p: &[DVec3], of: &[u32]) -> DVec3 {
    of.iter().map(|&i| p[i as usize]).sum()
}

/// Loop's weight β for a vertex of valence `n`.
fn beta(n: usize) -> f64 {
    if n == 3 {
        3.0 / 16.0
    } else {
        3.0 / (8.0 * n as f64)
    }
}

/// One level: the new positions (old vertices first, then one per edge) and triangles.
fn refine(p: &[DVec3], indices: &[u32]) -> (Vec<DVec3>, Vec<u32>) {
    let (edges, face_edges) = edges(indices);
    let (all, boundary) = neighbours(p.len(), &edges);
    let mut out: Vec<DVec3> = (0..p.len())
        .map(|v| {
            let (ring, border) = (&all[v], &boundary[v]);
            match (ring.len(), border.len()) {
                (0, _) => p[v],
                (n, 0) => (1.0 - n as f64 * beta(n)) * p[v] + beta(n) * sum(p, ring),
                (_, 2) => 0.75 * p[v] + 0.125 * sum(p, border),
                // A corner where more than two boundary edges meet stays where it is.
                _ => p[v],
            }
        })
        .collect();
    out.extend(edges.iter().map(|e| {
        let [a, b] = e.ends.map(|i| p[i as usize]);
        if e.faces == 2 {
            let [c, d] = e.opposite.map(|i| p[i as usize]);
            0.375 * (a + b) + 0.125 * (c + d)
        } else {
            0.5 * (a + b)
        }
    }));
    let first_edge = p.len() as u32;
    let mut tris = Vec::with_capacity(indices.len() * 4);
    for (t, fe) in indices.chunks_exact(3).zip(&face_edges) {
        let m = fe.map(|e| first_edge + e as u32);
        // Corner k with the midpoints of its two edges, then the middle triangle.
        tris.extend([
            t[0], m[0], m[2], m[0], t[1], m[1], m[2], m[1], t[2], m[0], m[1], m[2],
        ]);
    }
    (out, tris)
}

/// The limit positions of the vertices of a mesh.
fn limit(p: &[DVec3], indices: &[u32]) -> Vec<DVec3> {
    let (edges, _) = edges(indices);
    let (all, boundary) = neighbours(p.len(), &edges);
    (0..p.len())
        .map(|v| match (all[v].len(), boundary[v].len()) {
            (0, _) => p[v],
            (n, 0) => {
                let gamma = 1.0 / (n as f64 + 3.0 / (8.0 * beta(n)));
                (1.0 - n as f64 * gamma) * p[v] + gamma * sum(p, &all[v])
            }
            (_, 2) => 0.6 * p[v] + 0.2 * sum(p, &boundary[v]),
            _ => p[v],
        })
        .collect()
}

/// Triangles after `levels` of Loop subdivision, on the limit surface: (positions, indices,
/// per-vertex normals).
pub(super) fn subdivide(
    mut p: Vec<DVec3>,
    mut indices: Vec<u32>,
    levels: u32,
) -> (Vec<DVec3>, Vec<u32>, Vec<DVec3>) {
    for _ in 0..levels {
        (p, indices) = refine(&p, &indices);
    }
    let p = limit(&p, &indices);
    let mut normals = vec![DVec3::ZERO; p.len()];
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| p[i as usize]);
        // Twice the area times the unit normal: area weighting.
        let n = (b - a).cross(c - a);
        for &i in t {
            normals[i as usize] += n;
        }
    }
    let normals = normals.into_iter().map(|n| n.normalize_or_zero()).collect();
    (p, indices, normals)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A regular octahedron of radius 1: every vertex of valence 4.
    fn octahedron() -> (Vec<DVec3>, Vec<u32>) {
        let p = vec![
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_Z,
        ];
        let i = vec![
            0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5,
        ];
        (p, i)
    }

    #[test]
    fn each_level_splits_triangles_in_four_and_the_limit_is_a_smooth_closed_surface() {
        let (p, i) = octahedron();
        let (q, j, n) = subdivide(p, i, 3);
        assert_eq!(j.len(), 8 * 64 * 3);
        // Vertices: V - E + F = 2 for a sphere: F = 512, E = 768, V = 258.
        assert_eq!(q.len(), 258);
        // Symmetric about the centre, and inside the control octahedron's circumsphere.
        let centroid = q.iter().sum::<DVec3>() / q.len() as f64;
        assert!(centroid.length() < 1e-12, "{centroid}");
        for (v, n) in q.iter().zip(&n) {
            assert!(v.length() < 1.0 && v.length() > 0.4, "{v}");
            // Normals point outwards, close to the radial direction on this round surface.
            assert!(n.dot(v.normalize()) > 0.95, "{v} {n}");
        }
        // An old vertex stays on its axis, by symmetry.
        assert!(q[0].y.abs() < 1e-12 && q[0].z.abs() < 1e-12);
        // Every rule's weights sum to one: moving the control mesh moves the surface alike.
        let t = DVec3::new(3.0, -2.0, 0.5);
        let (p, i) = octahedron();
        let (moved, _, _) = subdivide(p.iter().map(|v| *v + t).collect(), i, 3);
        for (a, b) in moved.iter().zip(&q) {
            assert!((*a - (*b + t)).length() < 1e-12);
        }
    }

    #[test]
    fn the_boundary_of_an_open_mesh_follows_the_curve_rules() {
        // A flat fan of four triangles around a centre vertex: every point stays in the plane,
        // and the boundary corners, with two boundary neighbours each, move along the border.
        let p = vec![
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(0.0, -1.0, 0.0),
        ];
        let i = vec![0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1];
        let (q, j, n) = subdivide(p, i, 2);
        assert_eq!(j.len(), 4 * 16 * 3);
        for (v, n) in q.iter().zip(&n) {
            assert!(v.z.abs() < 1e-12);
            assert!((n.z - 1.0).abs() < 1e-9, "{n}");
        }
        // A boundary vertex of the control mesh: 3/4 v + 1/8 of its boundary neighbours per
        // level, then 3/5 v + 1/5 in the limit, which stays on the diamond's edge's side.
        assert!(
            q[1].x > 0.0 && q[1].x < 1.0 && q[1].y.abs() < 1e-12,
            "{}",
            q[1]
        );
    }
}
