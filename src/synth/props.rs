//! A prop beside a figure, as a scan or a scene holds one: a closed box standing on the
//! ground beside the figure's lowest point (docs/scans.md, "Props").

use std::collections::HashMap;

use super::FigureMesh;

/// `figure` with a closed, outward-oriented box of side `size` x its height standing on the
/// level of its lowest vertex, beside that vertex along the widest horizontal axis and
/// `gap` x the height away from the foot's side (0: touching). The height is along the
/// bounding box's longest axis. Each box face is a `grid` x `grid` mesh; the box's vertices
/// come after the figure's, whose indices are kept.
pub fn box_beside(figure: &FigureMesh, size: f64, gap: f64, grid: usize) -> FigureMesh {
    let points = &figure.vertices;
    let (lo, hi) = points
        .iter()
        .fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), p| {
            (
                std::array::from_fn(|i| lo[i].min(p[i])),
                std::array::from_fn(|i| hi[i].max(p[i])),
            )
        });
    let extent = |i: &usize| hi[*i] - lo[*i];
    let widest = |axes: &mut dyn Iterator<Item = usize>| {
        axes.max_by(|i, j| extent(i).total_cmp(&extent(j)))
            .unwrap_or(0)
    };
    let up = widest(&mut (0..3));
    let side_axis = widest(&mut (0..3).filter(|&i| i != up));
    let third = 3 - up - side_axis;
    let height = extent(&up);
    let Some(foot) = points.iter().min_by(|p, q| p[up].total_cmp(&q[up])) else {
        return figure.clone();
    };
    // The foot's side: the farthest point along the side axis near the ground and the foot.
    let foot_side = points
        .iter()
        .filter(|p| {
            p[up] < lo[up] + 0.05 * height
                && [side_axis, third]
                    .iter()
                    .all(|&i| (p[i] - foot[i]).abs() < 0.1 * height)
        })
        .map(|p| p[side_axis])
        .fold(foot[side_axis], f64::max);
    let side = size * height;
    let mut corner = [0.0; 3];
    corner[up] = lo[up];
    corner[side_axis] = foot_side + gap * height;
    corner[third] = foot[third] - side / 2.0;
    let (box_points, box_triangles) = box_mesh(corner, side, grid.max(1));
    let offset = points.len() as u32;
    FigureMesh {
        vertices: points.iter().copied().chain(box_points).collect(),
        triangles: figure
            .triangles
            .iter()
            .copied()
            .chain(box_triangles.iter().map(|t| t.map(|v| v + offset)))
            .collect(),
    }
}

/// A closed axis-aligned cube from `corner` with side `side`, each face a `grid` x `grid`
/// mesh, counter-clockwise seen from outside.
fn box_mesh(corner: [f64; 3], side: f64, grid: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut index: HashMap<[usize; 3], u32> = HashMap::new();
    let mut points: Vec<[f64; 3]> = Vec::new();
    let mut vertex = |c: [usize; 3]| -> u32 {
        *index.entry(c).or_insert_with(|| {
            points.push(std::array::from_fn(|i| {
                corner[i] + side * c[i] as f64 / grid as f64
            }));
            (points.len() - 1) as u32
        })
    };
    let mut triangles = Vec::new();
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for level in [0, grid] {
            for i in 0..grid {
                for j in 0..grid {
                    let at = |di: usize, dj: usize| {
                        let mut c = [0; 3];
                        c[axis] = level;
                        c[u] = i + di;
                        c[v] = j + dj;
                        c
                    };
                    let q = [at(0, 0), at(1, 0), at(1, 1), at(0, 1)].map(&mut vertex);
                    if level == grid {
                        triangles.extend([[q[0], q[1], q[2]], [q[0], q[2], q[3]]]);
                    } else {
                        triangles.extend([[q[0], q[2], q[1]], [q[0], q[3], q[2]]]);
                    }
                }
            }
        }
    }
    (points, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_box_is_closed_and_beside_the_figure() {
        let figure = FigureMesh {
            vertices: vec![[0.0, 0.0, 0.0], [0.08, 0.0, 0.0], [0.0, 1.0, 0.0]],
            triangles: vec![[0, 1, 2]],
        };
        let with = box_beside(&figure, 0.1, 0.05, 4);
        assert_eq!(with.vertices[..3], figure.vertices[..]);
        let box_points = &with.vertices[3..];
        // 6 faces of 5 x 5 lattice points, edges and corners shared.
        assert_eq!(box_points.len(), 5usize.pow(3) - 3usize.pow(3));
        assert_eq!(with.triangles.len(), 1 + 6 * 2 * 16);
        let min_x = box_points.iter().map(|p| p[0]).fold(f64::MAX, f64::min);
        assert!(
            (min_x - 0.13).abs() < 1e-12,
            "5% of the height beside the foot"
        );
        // Closed: every edge in exactly two triangles, once in each direction.
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for t in &with.triangles[1..] {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        assert!(edges
            .iter()
            .all(|(&(a, b), &c)| c == 1 && edges.get(&(b, a)) == Some(&1)));
    }
}
