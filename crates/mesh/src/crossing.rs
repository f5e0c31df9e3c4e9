//! Where triangle meshes cross each other or themselves: every pair of
//! triangles (of different meshes, or of one mesh sharing no corner) where
//! an edge of one passes through the interior of the other.
//!
//! Each mesh has a bounding volume hierarchy over its triangles, built once
//! for its triangles and refitted to the positions of each search (a
//! simulation's meshes keep their triangles, so a search after the first
//! builds nothing). Two meshes are searched by descending both hierarchies
//! where their boxes overlap. A mesh against itself is searched as Volino
//! and Magnenat-Thalmann do ("Efficient self-collision detection on
//! smoothly discretized surface animations using geometrical shape
//! regularity", 1994): a patch of the hierarchy is not searched when every
//! triangle's normal lies within a cone of less than a right angle about
//! some direction and its contour, projected along that direction, is one
//! simple closed polygon. Then the projection along the cone's axis takes
//! each triangle to a triangle of the same orientation, the interior edges
//! cancel, and a point of the plane is covered by as many triangles as the
//! contour winds around it: at most once, so no two triangles of the patch
//! overlap in projection, which any crossing would make them do. The
//! contour is the patch's edges with no triangle of the patch on the other
//! side, known from the triangles alone, so it is kept with the hierarchy;
//! a patch whose contour is not one cycle (a hole, a pinch), or a mesh not
//! consistently oriented, is always searched. The patches are made from the
//! triangles' adjacency (halved by distance in triangles from a triangle at
//! the patch's end), so they stay compact on the surface however the mesh
//! is folded; a mesh not searched against itself is halved in space where
//! it first was instead. The triangle test: each triangle's corners against
//! the other's plane (all on one side: no crossing), then each edge of
//! either against the other's interior (Möller & Trumbore 1997), touching
//! at the very edges not counted.
//!
//! Written here rather than taken from a collision crate: the search must
//! skip the triangles of one mesh that share a corner (a sheet's
//! neighbours always touch), cull a sheet's smooth patches against
//! themselves by their normals and contour (which no crate offers), tell
//! which meshes may cross at all, and give where in both triangles each
//! crossing is (for its UV); the hierarchy over glam's `DVec3` is a few
//! hundred lines.

use std::collections::{HashMap, HashSet};

use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// One triangle mesh taking part in a search: positions and triangles
/// (indices into the positions).
#[derive(Debug, Clone, Copy)]
pub struct Body<'a> {
    /// Vertex positions.
    pub positions: &'a [DVec3],
    /// Vertex indices of each triangle.
    pub triangles: &'a [[u32; 3]],
}

/// One triangle of one body: indices into the bodies searched and into
/// that body's triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct TriangleOf {
    /// The body.
    pub body: u32,
    /// The triangle in it.
    pub triangle: u32,
}

/// Two triangles that cross, and where: a point on the edge of one that
/// passes through the other, as barycentric weights of each triangle's
/// corners.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// The first triangle (the lower of the two).
    pub a: TriangleOf,
    /// The second.
    pub b: TriangleOf,
    /// The point in `a`'s corners.
    pub at_a: [f64; 3],
    /// The same point in `b`'s corners.
    pub at_b: [f64; 3],
}

/// At most this many triangles in a leaf of a hierarchy.
const LEAF: usize = 4;

/// A patch is culled against itself only where the cosine of its normals'
/// largest angle to its cone's axis is at least this: under a right angle
/// by about a thousandth of a radian, so that the cones' rounding cannot
/// matter.
const MIN_COS: f64 = 1e-3;

/// What each cone takes off the cosine of its angle for rounding: an angle
/// of 1.4e-6 radians near 0 (where a sine from its cosine is off by up to
/// about 1.5e-8), less near a right angle (where the cosine is exact to
/// about 1e-16).
const COS_SLACK: f64 = 1e-12;

/// A crossing search's hierarchies, one per body, kept between searches
/// (one per keyframe in a run): a body whose triangles are those of the
/// last search is only refitted.
#[derive(Debug, Default, Clone)]
pub struct CrossingSearch {
    /// Per body, its hierarchy.
    trees: Vec<Tree>,
    /// Per pair of bodies, whether they may cross.
    tested: Vec<bool>,
}

impl CrossingSearch {
    /// A search with no hierarchies yet.
    pub fn new() -> CrossingSearch {
        CrossingSearch::default()
    }

    /// Every crossing among `bodies`, sorted by `(a, b)`. `tested(i, j)`
    /// (with `i <= j`) says whether bodies `i` and `j` may cross at all
    /// (`i == j`: whether body `i` may cross itself, triangles sharing a
    /// corner never counting). Triangles with a non-finite corner are left
    /// out.
    pub fn find(
        &mut self,
        bodies: &[Body<'_>],
        tested: &dyn Fn(usize, usize) -> bool,
    ) -> Vec<Crossing> {
        // Which bodies may cross, looked up per pair.
        let count = bodies.len();
        self.tested.clear();
        self.tested.extend(
            (0..count * count)
                .map(|k| tested((k / count).min(k % count), (k / count).max(k % count))),
        );
        let tested = &self.tested;
        self.trees.resize_with(count, Tree::default);
        self.trees
            .par_iter_mut()
            .zip(bodies)
            .enumerate()
            .for_each(|(i, (tree, body))| {
                let itself = tested[i * count + i];
                if tree.triangles != body.triangles || (itself && !tree.contoured) {
                    *tree = Tree::build(body, itself);
                }
                tree.refit(body.positions);
            });
        // Each body against itself, then each pair whose boxes overlap, on
        // rayon's threads (sorted after, so the answer does not depend on
        // them).
        let trees = &self.trees;
        let tasks: Vec<(usize, usize)> = (0..count)
            .flat_map(|i| (i..count).map(move |j| (i, j)))
            .filter(|&(i, j)| {
                tested[i * count + j]
                    && !trees[i].nodes.is_empty()
                    && !trees[j].nodes.is_empty()
                    && (i == j || overlap(&trees[i].boxes[0], &trees[j].boxes[0]))
            })
            .collect();
        let mut found: Vec<Crossing> = tasks
            .into_par_iter()
            .flat_map_iter(|(i, j)| {
                let mut walk = Walk {
                    bodies: (i as u32, j as u32),
                    positions: (bodies[i].positions, bodies[j].positions),
                    trees: (&trees[i], &trees[j]),
                    found: Vec::new(),
                    projected: Vec::new(),
                    edges: Vec::new(),
                };
                if i == j {
                    walk.itself(0);
                } else {
                    walk.pair(0, 0);
                }
                walk.found
            })
            .collect();
        found.sort_unstable_by_key(|c| (c.a, c.b));
        found
    }
}

/// A box: its low and high corners (an empty box has low above high).
#[derive(Debug, Clone, Copy)]
struct Aabb {
    lo: DVec3,
    hi: DVec3,
}

impl Aabb {
    /// The box holding nothing.
    const EMPTY: Aabb = Aabb {
        lo: DVec3::INFINITY,
        hi: DVec3::NEG_INFINITY,
    };

    /// The smallest box holding both.
    fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
        }
    }
}

/// Whether two boxes overlap (touching counts; an empty box overlaps
/// nothing).
fn overlap(a: &Aabb, b: &Aabb) -> bool {
    a.lo.cmple(b.hi).all() && b.lo.cmple(a.hi).all()
}

/// A cone of directions about the unit vector `axis`: every normal it
/// bounds is within the angle whose cosine and sine are `cos` and `sin`.
/// Kept without trigonometry (cosines of sums), which a refit of every
/// node at every search would pay for.
#[derive(Debug, Clone, Copy)]
struct Cone {
    axis: DVec3,
    cos: f64,
    sin: f64,
}

impl Cone {
    /// The cone that bounds every direction.
    const ALL: Cone = Cone {
        axis: DVec3::Z,
        cos: -1.0,
        sin: 0.0,
    };

    /// The cone of the triangle with these corners (in their order): its
    /// normal, and the normal with its length (twice the area); every
    /// direction for a triangle with no area or a non-finite corner.
    fn of([p, q, r]: [DVec3; 3]) -> (Cone, DVec3) {
        let n = (q - p).cross(r - p);
        let length = n.length();
        if length > 0.0 && length.is_finite() {
            let cone = Cone {
                axis: n / length,
                cos: 1.0,
                sin: 0.0,
            };
            (cone, n)
        } else {
            (Cone::ALL, DVec3::ZERO)
        }
    }

    /// The cone about `sum` (the patch's normals weighted by area, summed)
    /// holding the cones `parts`: the angle to each part's axis plus its
    /// own (the cosine of their sum), a little more for rounding; every
    /// direction once that reaches a right angle, where it culls nothing.
    fn about(sum: DVec3, parts: &[Cone]) -> Cone {
        let length = sum.length();
        if !(length > 0.0 && length.is_finite()) {
            return Cone::ALL;
        }
        let axis = sum / length;
        let mut cos = 1.0f64;
        for part in parts {
            let (c, s) = (axis.dot(part.axis), axis.cross(part.axis).length());
            if !(part.cos > 0.0 && c > 0.0) {
                return Cone::ALL;
            }
            // Both angles are under a right angle: cos(a + b).
            cos = cos.min(c * part.cos - s * part.sin - COS_SLACK);
        }
        if cos.is_nan() || cos <= 0.0 {
            return Cone::ALL;
        }
        Cone {
            axis,
            cos,
            sin: (1.0 - cos * cos).max(0.0).sqrt(),
        }
    }
}

/// A node of a hierarchy: a leaf holds `order[first..first + count]`, an
/// inner node has its children at `first` and `first + 1`.
#[derive(Debug, Clone, Copy)]
struct Node {
    leaf: bool,
    first: u32,
    count: u32,
    /// Where the node's contour (its vertices in cycle order) is in
    /// `Tree::contour`, where it may be culled against itself: the mesh is
    /// consistently oriented and the contour is one cycle.
    contour: Option<(u32, u32)>,
}

/// A body's bounding volume hierarchy: built for its triangles, refitted to
/// each search's positions.
#[derive(Debug, Clone, Default)]
struct Tree {
    /// The triangles it was built for.
    triangles: Vec<[u32; 3]>,
    /// Whether it was built for the body against itself (patches made from
    /// the adjacency, their contours and cones kept).
    contoured: bool,
    /// The nodes, the root first, each parent before its children.
    nodes: Vec<Node>,
    /// The triangles' indices in leaf order (a node's triangles are a
    /// range of it, its slots).
    order: Vec<u32>,
    /// The triangles' corners in leaf order.
    sorted: Vec<[u32; 3]>,
    /// The contours of the nodes that have one (vertex cycles).
    contour: Vec<u32>,
    /// Per node, its box at the last refit.
    boxes: Vec<Aabb>,
    /// Per node, the cone of its normals at the last refit and their sum
    /// weighted by area (`contoured` only).
    cones: Vec<Cone>,
    normals: Vec<DVec3>,
    /// Per slot, its triangle's box at the last refit (empty for a
    /// triangle with a non-finite corner).
    triangle_boxes: Vec<Aabb>,
}

impl Tree {
    /// The hierarchy of `body`'s triangles: made from their adjacency, with
    /// contours, where the body is searched against itself (`itself`),
    /// else halved in space at its positions now.
    fn build(body: &Body<'_>, itself: bool) -> Tree {
        let triangles = body.triangles;
        let n = triangles.len();
        let mut tree = Tree {
            triangles: triangles.to_vec(),
            contoured: itself,
            order: (0..n as u32).collect(),
            ..Tree::default()
        };
        if n == 0 {
            return tree;
        }
        let (neighbours, oriented) = adjacency(triangles);
        let centroids: Vec<DVec3> = triangles
            .iter()
            .map(|t| t.iter().map(|&v| body.positions[v as usize]).sum::<DVec3>() / 3.0)
            .collect();
        let mut halver = Halver {
            neighbours: &neighbours,
            mark: vec![u32::MAX; n],
            distance: vec![u32::MAX; n],
            queue: Vec::new(),
        };
        tree.nodes.push(Node {
            leaf: true,
            first: 0,
            count: n as u32,
            contour: None,
        });
        let mut stack = vec![0usize];
        while let Some(k) = stack.pop() {
            let (first, count) = (tree.nodes[k].first as usize, tree.nodes[k].count as usize);
            if count <= LEAF {
                continue;
            }
            let part = &mut tree.order[first..first + count];
            if itself {
                halver.halve(part, k as u32);
            } else {
                halve_in_space(part, &centroids);
            }
            let half = count / 2;
            let children = tree.nodes.len() as u32;
            tree.nodes[k] = Node {
                leaf: false,
                first: children,
                count: count as u32,
                contour: None,
            };
            for (start, size) in [(first, half), (first + half, count - half)] {
                stack.push(tree.nodes.len());
                tree.nodes.push(Node {
                    leaf: true,
                    first: start as u32,
                    count: size as u32,
                    contour: None,
                });
            }
        }
        tree.sorted = tree.order.iter().map(|&t| triangles[t as usize]).collect();
        if itself && oriented {
            tree.contours();
        }
        tree
    }

    /// Each node's contour, from the leaves up: a leaf's is its triangles'
    /// edges whose reverse is not among them; an inner node's its
    /// children's, less the edges they share. Kept where it is one cycle.
    fn contours(&mut self) {
        let mut edges: Vec<Vec<(u32, u32)>> = vec![Vec::new(); self.nodes.len()];
        for k in (0..self.nodes.len()).rev() {
            let node = self.nodes[k];
            let all: Vec<(u32, u32)> = if node.leaf {
                let range = node.first as usize..(node.first + node.count) as usize;
                self.order[range]
                    .iter()
                    .flat_map(|&t| {
                        let [a, b, c] = self.triangles[t as usize];
                        [(a, b), (b, c), (c, a)]
                    })
                    .collect()
            } else {
                let (l, r) = (node.first as usize, node.first as usize + 1);
                let mut all = std::mem::take(&mut edges[l]);
                all.append(&mut std::mem::take(&mut edges[r]));
                all
            };
            let present: HashSet<(u32, u32)> = all.iter().copied().collect();
            let contour: Vec<(u32, u32)> = all
                .into_iter()
                .filter(|&(a, b)| !present.contains(&(b, a)))
                .collect();
            if let Some(cycle) = one_cycle(&contour) {
                let start = self.contour.len() as u32;
                self.contour.extend(cycle);
                self.nodes[k].contour = Some((start, self.contour.len() as u32));
            }
            edges[k] = contour;
        }
    }

    /// The boxes (and, for a contoured tree, the normals' cones) of every
    /// node at `positions`.
    fn refit(&mut self, positions: &[DVec3]) {
        self.triangle_boxes.clear();
        self.triangle_boxes.extend(self.sorted.iter().map(|t| {
            let [p, q, r] = t.map(|v| positions[v as usize]);
            if p.is_finite() && q.is_finite() && r.is_finite() {
                Aabb {
                    lo: p.min(q).min(r),
                    hi: p.max(q).max(r),
                }
            } else {
                Aabb::EMPTY
            }
        }));
        self.boxes.clear();
        self.boxes.resize(self.nodes.len(), Aabb::EMPTY);
        if self.contoured {
            self.cones.clear();
            self.cones.resize(self.nodes.len(), Cone::ALL);
            self.normals.clear();
            self.normals.resize(self.nodes.len(), DVec3::ZERO);
        }
        let mut parts = [Cone::ALL; LEAF];
        for k in (0..self.nodes.len()).rev() {
            let node = self.nodes[k];
            if node.leaf {
                let leaf = node.first as usize..(node.first + node.count) as usize;
                self.boxes[k] = self.triangle_boxes[leaf.clone()]
                    .iter()
                    .fold(Aabb::EMPTY, |b, t| b.union(t));
                if self.contoured {
                    let mut sum = DVec3::ZERO;
                    for (part, t) in parts.iter_mut().zip(&self.sorted[leaf.clone()]) {
                        let (cone, normal) = Cone::of(t.map(|v| positions[v as usize]));
                        *part = cone;
                        sum += normal;
                    }
                    self.normals[k] = sum;
                    self.cones[k] = Cone::about(sum, &parts[..leaf.len()]);
                }
            } else {
                let (l, r) = (node.first as usize, node.first as usize + 1);
                self.boxes[k] = self.boxes[l].union(&self.boxes[r]);
                if self.contoured {
                    let sum = self.normals[l] + self.normals[r];
                    self.normals[k] = sum;
                    self.cones[k] = Cone::about(sum, &[self.cones[l], self.cones[r]]);
                }
            }
        }
    }

    /// The slots of leaf `node`.
    fn leaf(&self, node: &Node) -> std::ops::Range<u32> {
        node.first..node.first + node.count
    }
}

/// Per triangle, the triangles across its edges (`u32::MAX`: none, or more
/// than one), and whether the triangles are consistently oriented (no edge
/// in more than two triangles, none twice the same way).
fn adjacency(triangles: &[[u32; 3]]) -> (Vec<[u32; 3]>, bool) {
    let mut by_edge: HashMap<(u32, u32), Vec<(u32, bool)>> = HashMap::new();
    for (t, &[a, b, c]) in triangles.iter().enumerate() {
        for (p, q) in [(a, b), (b, c), (c, a)] {
            by_edge
                .entry((p.min(q), p.max(q)))
                .or_default()
                .push((t as u32, p < q));
        }
    }
    let mut oriented = true;
    let mut neighbours = vec![[u32::MAX; 3]; triangles.len()];
    for (t, &[a, b, c]) in triangles.iter().enumerate() {
        for (k, (p, q)) in [(a, b), (b, c), (c, a)].into_iter().enumerate() {
            let Some(sharing) = by_edge.get(&(p.min(q), p.max(q))) else {
                continue;
            };
            match sharing.as_slice() {
                [_] => {}
                [x, y] => {
                    oriented &= x.1 != y.1;
                    neighbours[t][k] = if x.0 == t as u32 { y.0 } else { x.0 };
                }
                _ => oriented = false,
            }
        }
    }
    (neighbours, oriented)
}

/// The vertices of `edges` in cycle order where they make one directed
/// cycle (each vertex starting one edge and ending one), else `None`.
fn one_cycle(edges: &[(u32, u32)]) -> Option<Vec<u32>> {
    let mut next: HashMap<u32, u32> = HashMap::with_capacity(edges.len());
    for &(a, b) in edges {
        if next.insert(a, b).is_some() {
            return None;
        }
    }
    let &(start, _) = edges.first()?;
    let mut cycle = Vec::with_capacity(edges.len());
    let mut v = start;
    loop {
        cycle.push(v);
        v = *next.get(&v)?;
        if v == start || cycle.len() > edges.len() {
            break;
        }
    }
    (v == start && cycle.len() == edges.len()).then_some(cycle)
}

/// Halves a set of triangles by their distance in triangles from one at
/// its end (the last one reached from any), so that both halves stay
/// compact on the surface.
struct Halver<'a> {
    neighbours: &'a [[u32; 3]],
    /// Per triangle, the set it was last marked in.
    mark: Vec<u32>,
    /// Per triangle, its distance in the last walk.
    distance: Vec<u32>,
    queue: Vec<u32>,
}

impl Halver<'_> {
    /// Orders `part` (marked as set `set`) so that its first half is the
    /// triangles nearest one end of it, triangles it does not reach last.
    fn halve(&mut self, part: &mut [u32], set: u32) {
        for &t in part.iter() {
            self.mark[t as usize] = set;
            self.distance[t as usize] = u32::MAX;
        }
        let end = self.walk(part[0], set);
        for &t in part.iter() {
            self.distance[t as usize] = u32::MAX;
        }
        self.walk(end, set);
        let half = part.len() / 2;
        let distance = &self.distance;
        part.select_nth_unstable_by_key(half, |&t| (distance[t as usize], t));
    }

    /// A breadth-first walk from `from` over the triangles of set `set`,
    /// their distances kept; returns the last triangle reached.
    fn walk(&mut self, from: u32, set: u32) -> u32 {
        self.queue.clear();
        self.queue.push(from);
        self.distance[from as usize] = 0;
        let mut head = 0;
        while head < self.queue.len() {
            let t = self.queue[head] as usize;
            head += 1;
            for &u in &self.neighbours[t] {
                let u = u as usize;
                if u < self.mark.len() && self.mark[u] == set && self.distance[u] == u32::MAX {
                    self.distance[u] = self.distance[t] + 1;
                    self.queue.push(u as u32);
                }
            }
        }
        self.queue.last().copied().unwrap_or(from)
    }
}

/// Orders `part` so that its first half lies below its second along the
/// longest axis of its triangles' centroids.
fn halve_in_space(part: &mut [u32], centroids: &[DVec3]) {
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for &t in part.iter() {
        let c = centroids[t as usize];
        if c.is_finite() {
            (lo, hi) = (lo.min(c), hi.max(c));
        }
    }
    let extent = hi - lo;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let half = part.len() / 2;
    part.select_nth_unstable_by(half, |&a, &b| {
        centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
    });
}

/// One search between bodies `bodies.0` and `bodies.1` (the same body: it
/// against itself), its crossings and scratch space.
struct Walk<'a> {
    bodies: (u32, u32),
    positions: (&'a [DVec3], &'a [DVec3]),
    trees: (&'a Tree, &'a Tree),
    found: Vec<Crossing>,
    /// A contour projected (scratch).
    projected: Vec<DVec2>,
    /// A projected contour's edges by their low x (scratch).
    edges: Vec<(f64, f64, usize)>,
}

impl Walk<'_> {
    /// The crossings within node `k` of the one body.
    fn itself(&mut self, k: usize) {
        let tree = self.trees.0;
        if self.culled(k) {
            return;
        }
        let node = tree.nodes[k];
        if node.leaf {
            let leaf = tree.leaf(&node);
            for s in leaf.clone() {
                for t in s + 1..leaf.end {
                    self.test(s, t);
                }
            }
        } else {
            let l = node.first as usize;
            self.itself(l);
            self.itself(l + 1);
            self.pair(l, l + 1);
        }
    }

    /// The crossings between node `a` of the first body's tree and node `b`
    /// of the second's.
    fn pair(&mut self, a: usize, b: usize) {
        let (ta, tb) = self.trees;
        if !overlap(&ta.boxes[a], &tb.boxes[b]) {
            return;
        }
        let (na, nb) = (ta.nodes[a], tb.nodes[b]);
        match (na.leaf, nb.leaf) {
            (true, true) => {
                // Only the triangles whose boxes reach the other leaf's.
                for s in ta.leaf(&na) {
                    if !overlap(&ta.triangle_boxes[s as usize], &tb.boxes[b]) {
                        continue;
                    }
                    for t in tb.leaf(&nb) {
                        self.test(s, t);
                    }
                }
            }
            (false, true) => {
                self.pair(na.first as usize, b);
                self.pair(na.first as usize + 1, b);
            }
            (true, false) => {
                self.pair(a, nb.first as usize);
                self.pair(a, nb.first as usize + 1);
            }
            (false, false) => {
                // The larger box is split.
                let size = |x: &Aabb| (x.hi - x.lo).element_sum();
                if size(&ta.boxes[a]) >= size(&tb.boxes[b]) {
                    self.pair(na.first as usize, b);
                    self.pair(na.first as usize + 1, b);
                } else {
                    self.pair(a, nb.first as usize);
                    self.pair(a, nb.first as usize + 1);
                }
            }
        }
    }

    /// The triangle in slot `s` of the first body against the one in slot
    /// `t` of the second (of one body: skipped where they share a corner).
    fn test(&mut self, s: u32, t: u32) {
        let (ta, tb) = self.trees;
        if !overlap(
            &ta.triangle_boxes[s as usize],
            &tb.triangle_boxes[t as usize],
        ) {
            return;
        }
        let (vs, vt) = (ta.sorted[s as usize], tb.sorted[t as usize]);
        let same = self.bodies.0 == self.bodies.1;
        if same && vs.iter().any(|v| vt.contains(v)) {
            return;
        }
        let (a, b) = (
            TriangleOf {
                body: self.bodies.0,
                triangle: ta.order[s as usize],
            },
            TriangleOf {
                body: self.bodies.1,
                triangle: tb.order[t as usize],
            },
        );
        let cs = vs.map(|v| self.positions.0[v as usize]);
        let ct = vt.map(|v| self.positions.1[v as usize]);
        // The lower triangle first (where on the edges the test reports
        // depends on the order).
        let crossing = if a < b {
            triangles_cross(&cs, &ct).map(|(at_a, at_b)| Crossing { a, b, at_a, at_b })
        } else {
            triangles_cross(&ct, &cs).map(|(at_b, at_a)| Crossing {
                a: b,
                b: a,
                at_a: at_b,
                at_b: at_a,
            })
        };
        self.found.extend(crossing);
    }

    /// Whether node `k` of the one body cannot cross itself: its normals
    /// lie within a cone of less than a right angle and its contour,
    /// projected along the cone's axis, is a simple polygon (see the module
    /// notes). Where unsure (near-touching edges, rounding), not culled.
    fn culled(&mut self, k: usize) -> bool {
        let tree = self.trees.0;
        let Some((start, end)) = tree.nodes[k].contour else {
            return false;
        };
        let Some(cone) = tree.cones.get(k) else {
            return false;
        };
        if cone.cos.is_nan() || cone.cos < MIN_COS {
            return false;
        }
        let (u, w) = cone.axis.any_orthonormal_pair();
        let positions = self.positions.0;
        self.projected.clear();
        self.projected
            .extend(tree.contour[start as usize..end as usize].iter().map(|&v| {
                let p = positions[v as usize];
                DVec2::new(p.dot(u), p.dot(w))
            }));
        simple_polygon(&self.projected, &mut self.edges)
    }
}

/// Whether the closed polygon `p` is simple: no edge meets another but
/// its neighbours at their shared corner, none turns back along the one
/// before it. Near-touching (within a billionth of its size) counts as
/// meeting. `edges` is scratch space.
fn simple_polygon(p: &[DVec2], edges: &mut Vec<(f64, f64, usize)>) -> bool {
    let n = p.len();
    if n < 3 || !p.iter().all(|q| q.is_finite()) {
        return false;
    }
    let (lo, hi) = p
        .iter()
        .fold((p[0], p[0]), |(lo, hi), &q| (lo.min(q), hi.max(q)));
    let tolerance = 1e-9 * (hi - lo).max_element();
    if tolerance.is_nan() || tolerance <= 0.0 {
        return false;
    }
    let edge = |i: usize| (p[i], p[(i + 1) % n]);
    // No edge too short to have a direction, none turning back.
    for i in 0..n {
        let (a, b) = edge(i);
        let c = p[(i + 2) % n];
        let (d, e) = (b - a, c - b);
        if d.length() <= tolerance {
            return false;
        }
        if d.perp_dot(e).abs() <= 1e-9 * d.length() * e.length() && d.dot(e) < 0.0 {
            return false;
        }
    }
    // Every two edges not neighbours, swept along x.
    edges.clear();
    edges.extend((0..n).map(|i| {
        let (a, b) = edge(i);
        (a.x.min(b.x), a.x.max(b.x), i)
    }));
    edges.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    for (k, &(_, right, i)) in edges.iter().enumerate() {
        let (a, b) = edge(i);
        for &(left, _, j) in &edges[k + 1..] {
            if left > right + tolerance {
                break;
            }
            let apart = (i + n - j) % n;
            if apart == 1 || apart == n - 1 {
                continue;
            }
            let (c, d) = edge(j);
            if a.y.min(b.y) > c.y.max(d.y) + tolerance || c.y.min(d.y) > a.y.max(b.y) + tolerance {
                continue;
            }
            // Apart where one edge's line has the other's ends strictly on
            // one side of it.
            let side = |a: DVec2, b: DVec2, c: DVec2, d: DVec2| {
                let along = b - a;
                let t = tolerance * along.length();
                let (x, y) = (along.perp_dot(c - a), along.perp_dot(d - a));
                (x > t && y > t) || (x < -t && y < -t)
            };
            if !(side(a, b, c, d) || side(c, d, a, b)) {
                return false;
            }
        }
    }
    true
}

/// Whether triangles `a` and `b` cross (an edge of either passes through
/// the other's interior), and if so where: the point, as barycentric
/// weights of `a`'s corners and of `b`'s.
pub fn triangles_cross(a: &[DVec3; 3], b: &[DVec3; 3]) -> Option<([f64; 3], [f64; 3])> {
    // Möller's interval test first (most pairs the grid hands over are
    // neighbours of one smooth sheet, which it rejects cheaply); the edges
    // are then tested for where they cross.
    let (na, nb) = (
        (a[1] - a[0]).cross(a[2] - a[0]),
        (b[1] - b[0]).cross(b[2] - b[0]),
    );
    let da = a.map(|p| (p - b[0]).dot(nb));
    let db = b.map(|p| (p - a[0]).dot(na));
    let one_side = |d: &[f64; 3]| d.iter().all(|&x| x > 0.0) || d.iter().all(|&x| x < 0.0);
    if one_side(&da) || one_side(&db) {
        return None;
    }
    let line = na.cross(nb);
    if let (Some(ia), Some(ib)) = (interval(a, &da, line), interval(b, &db, line))
        && (ia.1 < ib.0 || ib.1 < ia.0)
    {
        return None;
    }
    edges_cross(a, b)
}

/// Where an edge of `a` or `b` passes through the other's interior, the
/// first found (see [`triangles_cross`]).
fn edges_cross(a: &[DVec3; 3], b: &[DVec3; 3]) -> Option<([f64; 3], [f64; 3])> {
    for k in 0..3 {
        let (i, j) = (k, (k + 1) % 3);
        if let Some((t, inside)) = segment_through_triangle(a[i], a[j], b) {
            let mut on_edge = [0.0; 3];
            on_edge[i] = 1.0 - t;
            on_edge[j] = t;
            return Some((on_edge, inside));
        }
    }
    for k in 0..3 {
        let (i, j) = (k, (k + 1) % 3);
        if let Some((t, inside)) = segment_through_triangle(b[i], b[j], a) {
            let mut on_edge = [0.0; 3];
            on_edge[i] = 1.0 - t;
            on_edge[j] = t;
            return Some((inside, on_edge));
        }
    }
    None
}

/// Where a triangle with corners `t`, at signed distances `d` from the
/// other's plane (not all on one side), meets that plane, as an interval
/// along `line` (the planes' common direction): `None` where a corner lies
/// in the plane (the edge tests decide).
fn interval(t: &[DVec3; 3], d: &[f64; 3], line: DVec3) -> Option<(f64, f64)> {
    if d.contains(&0.0) {
        return None;
    }
    // The corner alone on its side.
    let alone = (0..3).find(|&i| {
        (d[i] > 0.0) != (d[(i + 1) % 3] > 0.0) && (d[i] > 0.0) != (d[(i + 2) % 3] > 0.0)
    })?;
    let p = t.map(|c| c.dot(line));
    let at = |j: usize| p[j] + (p[alone] - p[j]) * d[j] / (d[j] - d[alone]);
    let (x, y) = (at((alone + 1) % 3), at((alone + 2) % 3));
    Some((x.min(y), x.max(y)))
}

/// Where the segment `p -> q` passes through the interior of `tri`
/// (Möller–Trumbore; touching at the very edges, or lying in its plane, is
/// not a crossing): the fraction along the segment and the barycentric
/// weights of the triangle's corners.
pub fn segment_through_triangle(p: DVec3, q: DVec3, tri: &[DVec3; 3]) -> Option<(f64, [f64; 3])> {
    const EPS: f64 = 1e-9;
    let d = q - p;
    let e1 = tri[1] - tri[0];
    let e2 = tri[2] - tri[0];
    let h = d.cross(e2);
    let det = e1.dot(h);
    let scale = d.length() * e1.length() * e2.length();
    if det.abs() <= EPS * scale {
        return None;
    }
    let s = p - tri[0];
    let b1 = s.dot(h) / det;
    let qv = s.cross(e1);
    let b2 = d.dot(qv) / det;
    let t = e2.dot(qv) / det;
    (b1 > EPS && b2 > EPS && b1 + b2 < 1.0 - EPS && t > EPS && t < 1.0 - EPS)
        .then_some((t, [1.0 - b1 - b2, b1, b2]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::flat_sheet;

    fn body(mesh: &crate::Mesh) -> Body<'_> {
        Body {
            positions: &mesh.positions,
            triangles: &mesh.triangles,
        }
    }

    /// Every crossing by testing every pair of triangles.
    fn brute_force(bodies: &[Body<'_>], tested: &dyn Fn(usize, usize) -> bool) -> Vec<Crossing> {
        let mut found = Vec::new();
        let all: Vec<TriangleOf> = bodies
            .iter()
            .enumerate()
            .flat_map(|(b, body)| {
                (0..body.triangles.len()).map(move |t| TriangleOf {
                    body: b as u32,
                    triangle: t as u32,
                })
            })
            .collect();
        for (i, &a) in all.iter().enumerate() {
            for &b in &all[i + 1..] {
                if !tested(a.body as usize, b.body as usize) {
                    continue;
                }
                let (ta, tb) = (
                    bodies[a.body as usize].triangles[a.triangle as usize],
                    bodies[b.body as usize].triangles[b.triangle as usize],
                );
                if a.body == b.body && ta.iter().any(|v| tb.contains(v)) {
                    continue;
                }
                let pa = ta.map(|v| bodies[a.body as usize].positions[v as usize]);
                let pb = tb.map(|v| bodies[b.body as usize].positions[v as usize]);
                // Left out: a triangle with a non-finite corner.
                if !pa.iter().chain(&pb).all(|p| p.is_finite()) {
                    continue;
                }
                if let Some((at_a, at_b)) = triangles_cross(&pa, &pb) {
                    found.push(Crossing { a, b, at_a, at_b });
                }
            }
        }
        found
    }

    /// A sheet rolled about the x axis through `turns` turns, its radius
    /// growing by `pitch` per turn (a clean spiral) and wobbling by
    /// `wobble` at 1.25 waves per turn, which makes a turn pass through the
    /// one before it.
    fn rolled(turns: f64, pitch: f64, wobble: f64) -> crate::Mesh {
        let mut mesh = flat_sheet(4.0, 1.0, 9, 60);
        for p in &mut mesh.positions {
            let angle = p.y * turns * std::f64::consts::TAU;
            let radius = 1.0 + pitch * p.y * turns + wobble * (1.25 * angle).sin();
            *p = DVec3::new(p.x, radius * angle.cos(), radius * angle.sin());
        }
        mesh
    }

    #[test]
    fn the_search_finds_what_testing_every_pair_finds() {
        let sheet = flat_sheet(2.0, 2.0, 8, 8);
        let mut tilted = sheet.clone();
        for p in &mut tilted.positions {
            *p = DVec3::new(p.x + 0.37, p.z + 0.41, p.y - 1.03);
        }
        let roll = rolled(1.6, 0.0, 0.1);
        // A body not tested against itself (as a part) partly beside the
        // others.
        let mut beside = roll.clone();
        for p in &mut beside.positions {
            p.x += 1.7;
        }
        let bodies = [body(&sheet), body(&tilted), body(&roll), body(&beside)];
        // One search used for every rule, so that its hierarchies are kept
        // from one to the next or built again where a body is now tested
        // against itself.
        let mut search = CrossingSearch::new();
        let rules: [&dyn Fn(usize, usize) -> bool; 3] = [
            &|i, j| (i != 1 || j != 1) && (i != 3 || j != 3),
            &|_, _| true,
            &|i, j| i != j,
        ];
        for tested in rules {
            let mut found = search.find(&bodies, tested);
            let mut all = brute_force(&bodies, tested);
            assert!(all.len() > 10, "{}", all.len());
            let key = |c: &Crossing| (c.a, c.b);
            found.sort_by_key(key);
            all.sort_by_key(key);
            let missed: Vec<_> = all.iter().filter(|c| !found.contains(c)).map(key).collect();
            let extra: Vec<_> = found.iter().filter(|c| !all.contains(c)).map(key).collect();
            assert_eq!(found, all, "missed {missed:?}, extra {extra:?}");
        }
    }

    #[test]
    fn a_sheet_rolled_through_itself_crosses_and_one_rolled_outwards_does_not() {
        let mut search = CrossingSearch::new();
        let all = |_: usize, _: usize| true;
        let through = rolled(1.5, 0.0, 0.1);
        let found = search.find(&[body(&through)], &all);
        assert!(!found.is_empty());
        // Each crossing is where it says, in both triangles.
        for c in &found {
            let at = |t: TriangleOf, w: [f64; 3]| {
                let tri = through.triangles[t.triangle as usize];
                (0..3)
                    .map(|k| through.positions[tri[k] as usize] * w[k])
                    .sum::<DVec3>()
            };
            assert!(at(c.a, c.at_a).distance(at(c.b, c.at_b)) < 1e-9);
            assert!(c.a < c.b && c.a.body == 0 && c.b.body == 0);
        }
        let apart = rolled(1.5, 0.3, 0.0);
        assert_eq!(search.find(&[body(&apart)], &all), Vec::new());
        // Not looked at when the body may not cross itself.
        assert_eq!(search.find(&[body(&through)], &|_, _| false), Vec::new());
    }

    #[test]
    fn the_interval_test_rejects_no_pair_whose_edges_cross() {
        // Random triangles in a small box: the quick rejections must agree
        // with testing every edge, crossing or not.
        let mut state = 7u64;
        let mut random = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut point = || DVec3::new(random(), random(), random());
        let mut crossing = 0;
        for _ in 0..20_000 {
            let a = [point(), point(), point()];
            let b = [point(), point(), point()];
            let quick = triangles_cross(&a, &b);
            assert_eq!(quick, edges_cross(&a, &b), "{a:?} {b:?}");
            crossing += usize::from(quick.is_some());
        }
        assert!(crossing > 1000, "{crossing}");
    }

    #[test]
    fn touching_at_an_edge_or_lying_apart_is_not_a_crossing() {
        let a = [DVec3::ZERO, DVec3::X, DVec3::Y];
        // Standing on a's edge, and hanging just above a.
        let on_edge = [
            DVec3::new(0.2, 0.0, 0.0),
            DVec3::new(0.6, 0.0, 0.0),
            DVec3::new(0.4, 0.0, 1.0),
        ];
        assert_eq!(triangles_cross(&a, &on_edge), None);
        let above = a.map(|p| p + DVec3::new(0.1, 0.1, 1e-6));
        assert_eq!(triangles_cross(&a, &above), None);
        // Pushed through a's middle.
        let through = [
            DVec3::new(0.2, 0.2, -0.5),
            DVec3::new(0.3, 0.2, 0.5),
            DVec3::new(0.2, 0.6, 0.5),
        ];
        let (at_a, at_b) = triangles_cross(&a, &through).expect("crosses");
        let point = |tri: &[DVec3; 3], w: [f64; 3]| tri[0] * w[0] + tri[1] * w[1] + tri[2] * w[2];
        assert!(point(&a, at_a).distance(point(&through, at_b)) < 1e-12);
        assert!(point(&a, at_a).z.abs() < 1e-12);
    }

    #[test]
    fn a_huge_or_broken_triangle_is_searched_or_left_out() {
        let sheet = flat_sheet(2.0, 2.0, 6, 6);
        let huge = [
            DVec3::new(-1e12, 0.5, -1e12),
            DVec3::new(1e12, 0.5, -1e12),
            DVec3::new(0.0, 0.5, 1e12),
        ];
        let broken = [DVec3::NAN, DVec3::ONE, DVec3::ZERO];
        let tri = [[0u32, 1, 2]];
        let bodies = [
            body(&sheet),
            Body {
                positions: &huge,
                triangles: &tri,
            },
            Body {
                positions: &broken,
                triangles: &tri,
            },
        ];
        let mut search = CrossingSearch::new();
        let found = search.find(&bodies, &|_, _| true);
        // The huge triangle cuts the sheet (the plane y = 0.5 across it);
        // the broken one is left out.
        assert!(
            found.iter().all(|c| c.a.body == 0 && c.b.body == 1),
            "{found:?}"
        );
        assert!(!found.is_empty());
        assert_eq!(found, brute_force(&bodies, &|_, _| true));
    }

    /// A ramp of `turns` turns about the z axis, its width along the
    /// radius (1 to 1.5): rising by `rise` per radian and tilted across by
    /// `tilt` times the angle, so that where `tilt` outweighs `rise` a turn
    /// passes through the one below it along a circle, every normal within
    /// a narrow cone about z all the same.
    fn ramp(turns: f64, rise: f64, tilt: f64) -> crate::Mesh {
        crate::generate::parametric_grid(5, (turns * 40.0) as usize, |uv| {
            let (r, angle) = (1.0 + 0.5 * uv.x, uv.y * turns * std::f64::consts::TAU);
            let z = rise * angle + tilt * angle * (r - 1.25);
            DVec3::new(r * angle.cos(), r * angle.sin(), z)
        })
    }

    #[test]
    fn a_ramp_whose_normals_lie_in_a_narrow_cone_is_searched_where_its_contour_overlaps() {
        let mut search = CrossingSearch::new();
        let all = |_: usize, _: usize| true;
        let through = ramp(1.6, 0.005, 0.05);
        let found = search.find(&[body(&through)], &all);
        let root = search.trees[0].cones[0];
        assert!(root.cos >= MIN_COS, "{root:?}");
        assert!(!found.is_empty());
        assert_eq!(found, brute_force(&[body(&through)], &all));
        // Rising without the tilt: the turns apart, clean, though searched
        // (one turn lies over the next, so the contour is not simple).
        let apart = ramp(1.6, 0.05, 0.0);
        assert_eq!(search.find(&[body(&apart)], &all), Vec::new());
        // The root culled only where its contour projects simple: under
        // one turn, not past one.
        for (mesh, culled) in [(ramp(0.8, 0.05, 0.02), true), (through, false)] {
            let mut tree = Tree::build(&body(&mesh), true);
            tree.refit(&mesh.positions);
            let mut walk = Walk {
                bodies: (0, 0),
                positions: (&mesh.positions, &mesh.positions),
                trees: (&tree, &tree),
                found: Vec::new(),
                projected: Vec::new(),
                edges: Vec::new(),
            };
            assert_eq!(walk.culled(0), culled);
        }
    }

    #[test]
    fn a_polygon_is_simple_unless_its_edges_meet_or_turn_back() {
        let mut scratch = Vec::new();
        let square = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(DVec2::from);
        assert!(simple_polygon(&square, &mut scratch));
        let bow_tie = [(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.0, 1.0)].map(DVec2::from);
        assert!(!simple_polygon(&bow_tie, &mut scratch));
        // Twice round a centre (a pentagram): simple at every corner, its
        // edges cross.
        let star: Vec<DVec2> = (0..5)
            .map(|k| {
                let a = f64::from(k) * 4.0 * std::f64::consts::PI / 5.0;
                DVec2::new(a.cos(), a.sin())
            })
            .collect();
        assert!(!simple_polygon(&star, &mut scratch));
        // Touching at a corner, and turning back along an edge.
        let touching = [
            (0.0, 0.0),
            (2.0, 0.0),
            (1.0, 1.0),
            (2.0, 2.0),
            (0.0, 2.0),
            (1.0, 1.0),
        ]
        .map(DVec2::from);
        assert!(!simple_polygon(&touching, &mut scratch));
        let back = [(0.0, 0.0), (2.0, 0.0), (1.0, 0.0), (1.0, 1.0)].map(DVec2::from);
        assert!(!simple_polygon(&back, &mut scratch));
    }

    /// A test sheet of one of four kinds, `k` in 0..1 its shape's
    /// parameters: rolled (through itself or not), folded about a line
    /// (through itself past a half turn), crumpled at random, or a ramp.
    fn shape(kind: u8, k: [f64; 4], seed: u64) -> crate::Mesh {
        match kind {
            0 => {
                let mut mesh = flat_sheet(2.0, 1.0, 5, 30);
                let (turns, pitch, wobble) = (0.5 + 2.0 * k[0], 0.3 * k[1] - 0.05, 0.2 * k[2]);
                for p in &mut mesh.positions {
                    let angle = p.y * turns * std::f64::consts::TAU;
                    let radius = 0.5 + pitch * p.y * turns + wobble * (1.25 * angle).sin();
                    *p = DVec3::new(p.x, radius * angle.cos(), radius * angle.sin());
                }
                mesh
            }
            1 => {
                // Folded about y = 0.5 by 150 to 210 degrees, the folded
                // half shifted along x and bent a little.
                let mut mesh = flat_sheet(1.0, 1.0, 12, 12);
                let fold = (150.0 + 60.0 * k[0]).to_radians();
                for p in &mut mesh.positions {
                    if p.y > 0.5 {
                        let d = p.y - 0.5;
                        let bend = 0.3 * (k[1] - 0.5) * (p.x * 3.0).sin();
                        *p = DVec3::new(
                            p.x + 0.2 * k[2] * d,
                            0.5 + d * fold.cos(),
                            d * fold.sin() + bend * d,
                        );
                    }
                }
                mesh
            }
            2 => {
                let mut mesh = flat_sheet(1.0, 1.0, 10, 10);
                mesh.positions =
                    crate::generate::jittered(&mesh.positions, 0.05 + 0.4 * k[0], seed);
                mesh
            }
            _ => ramp(0.8 + k[0], 0.04 * k[1] - 0.02, 0.1 * k[2] - 0.05),
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]

        /// Up to three sheets of the kinds above, each moved to overlap the
        /// others, some searched against themselves and some not, searched
        /// at two poses with one search (built, then refitted): what
        /// testing every pair finds.
        #[test]
        fn the_search_finds_what_testing_every_pair_finds_on_any_sheets(
            sheets in proptest::collection::vec(
                (0u8..4, proptest::array::uniform4(0.0f64..1.0), proptest::array::uniform3(-0.5f64..0.5), proptest::bool::ANY),
                1..4,
            ),
            seed in 0u64..1000,
            moved in 0.0f64..0.3,
        ) {
            let meshes: Vec<crate::Mesh> = sheets
                .iter()
                .map(|&(kind, k, offset, _)| {
                    let mut mesh = shape(kind, k, seed);
                    for p in &mut mesh.positions {
                        *p += DVec3::from(offset);
                    }
                    mesh
                })
                .collect();
            let itself: Vec<bool> = sheets.iter().map(|s| s.3).collect();
            let tested = |i: usize, j: usize| i != j || itself[i];
            let mut search = CrossingSearch::new();
            for pose in 0..2 {
                let moved_meshes: Vec<crate::Mesh> = meshes
                    .iter()
                    .enumerate()
                    .map(|(b, mesh)| {
                        let mut mesh = mesh.clone();
                        // The second pose: each sheet bent and shifted.
                        for p in &mut mesh.positions {
                            let s = moved * f64::from(pose) * (b as f64 + 1.0);
                            *p += DVec3::new(s * (3.0 * p.y).sin(), s * p.x, -s);
                        }
                        mesh
                    })
                    .collect();
                let bodies: Vec<Body<'_>> = moved_meshes.iter().map(body).collect();
                let found = search.find(&bodies, &tested);
                let all = brute_force(&bodies, &tested);
                proptest::prop_assert_eq!(found, all);
            }
        }
    }
}
