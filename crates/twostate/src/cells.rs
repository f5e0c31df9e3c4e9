//! The growth variations of the floral blossom paper §4.2, per
//! triangle ("cell") of an organ taken in two states: each cell's growth
//! property ellipse (major axis along the mesh's `v`, the organ's length;
//! minor axis across it), the primary growth direction (the rotation from
//! the bud's ellipse frame to the open one's, a quaternion), the adaxial and
//! abaxial variations (the major and minor axes' length ratios), and the
//! whole in-plane deformation the ellipse summarises, kept so the open
//! state is met exactly.

use anthesis_mesh::Mesh;
use glam::{DMat2, DMat3, DQuat, DVec2, DVec3};

use crate::TwoStateError;

/// A cell's growth property ellipse in one state: an orthonormal frame
/// (minor axis, major axis, normal to the inner side) and the two radii.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipse {
    /// Columns: the minor axis (across, `major × normal`), the major axis
    /// (along the mesh's `v` direction, base to tip) and the unit normal of
    /// the inner side (the winding convention's normal).
    pub frame: DMat3,
    /// Length of the surface's `v` derivative (length per unit of `v`).
    pub major_radius: f64,
    /// Length of the surface's `u` derivative (length per unit of `u`).
    pub minor_radius: f64,
}

/// What the two states say about one cell (triangle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellGrowth {
    /// The cell's ellipse in the bud.
    pub bud: Ellipse,
    /// The cell's ellipse in the open state.
    pub open: Ellipse,
    /// The primary growth direction: the rotation taking the bud ellipse's
    /// frame onto the open one's (so the bud's major axis onto the open
    /// major axis), with a non-negative scalar part.
    pub direction: DQuat,
    /// The adaxial growth variation: open major radius / bud major radius.
    pub adaxial: f64,
    /// The abaxial growth variation: open minor radius / bud minor radius.
    pub abaxial: f64,
    /// The in-plane deformation in the bud ellipse's (minor, major)
    /// coordinates that, followed by `direction`, takes the bud cell onto
    /// the open cell exactly. Its diagonal is (`abaxial`, `adaxial`) when
    /// the cell grows along its axes; off-diagonal terms are shear, which an
    /// ellipse cannot show but the open shape may need.
    pub in_plane: DMat2,
}

impl CellGrowth {
    /// The deformation gradient at a point of the way: the bud cell's edge
    /// vectors times this give the in-between cell's. `turn` is the slerp
    /// fraction of the direction (0 = bud frame, 1 = open frame) and
    /// `growth` the fraction of the in-plane change (0 = none, 1 = the open
    /// cell's); each ratio goes from 1 to its open value as the paper's
    /// G(t) does.
    pub fn transform(&self, turn: f64, growth: f64) -> DMat3 {
        let rotation = DMat3::from_quat(DQuat::IDENTITY.slerp(self.direction, turn));
        let m = DMat2::IDENTITY + (self.in_plane - DMat2::IDENTITY) * growth;
        let in_plane = DMat3::from_cols(
            DVec3::new(m.x_axis.x, m.x_axis.y, 0.0),
            DVec3::new(m.y_axis.x, m.y_axis.y, 0.0),
            DVec3::Z,
        );
        rotation * self.bud.frame * in_plane * self.bud.frame.transpose()
    }
}

/// The ellipse of triangle `t` of a mesh with `positions` (the UVs and
/// triangles of `mesh`). `state` names the state in errors.
fn ellipse(
    mesh: &Mesh,
    positions: &[DVec3],
    t: usize,
    state: &'static str,
) -> Result<(Ellipse, [DVec3; 2]), TwoStateError> {
    let [a, b, c] = mesh.triangles[t].map(|i| i as usize);
    let (e1, e2) = (positions[b] - positions[a], positions[c] - positions[a]);
    let (w1, w2) = (mesh.uvs[b] - mesh.uvs[a], mesh.uvs[c] - mesh.uvs[a]);
    let uv = DMat2::from_cols(w1, w2);
    if uv.determinant().abs() < 1e-14 {
        return Err(TwoStateError::FlatUvs { triangle: t });
    }
    // Surface derivatives: [x_u x_v] = [e1 e2] · uv⁻¹.
    let inv = uv.inverse();
    let x_u = e1 * inv.x_axis.x + e2 * inv.x_axis.y;
    let x_v = e1 * inv.y_axis.x + e2 * inv.y_axis.y;
    let normal = e1.cross(e2);
    if normal.length() < 1e-14 || x_v.length() < 1e-14 || x_u.length() < 1e-14 {
        return Err(TwoStateError::FlatTriangle { triangle: t, state });
    }
    let normal = normal.normalize();
    // The major axis along v, kept in the triangle's plane.
    let major = (x_v - normal * normal.dot(x_v)).normalize();
    let minor = major.cross(normal);
    Ok((
        Ellipse {
            frame: DMat3::from_cols(minor, major, normal),
            major_radius: x_v.length(),
            minor_radius: x_u.length(),
        },
        [e1, e2],
    ))
}

/// The growth of every cell between `bud` (positions, UVs and triangles)
/// and `open` positions (same vertices, same order).
pub fn cell_growth(bud: &Mesh, open: &[DVec3]) -> Result<Vec<CellGrowth>, TwoStateError> {
    (0..bud.triangles.len())
        .map(|t| {
            let (bud_ellipse, bud_edges) = ellipse(bud, &bud.positions, t, "bud")?;
            let (open_ellipse, open_edges) = ellipse(bud, open, t, "open state")?;
            let rotation = open_ellipse.frame * bud_ellipse.frame.transpose();
            let mut direction = DQuat::from_mat3(&rotation).normalize();
            if direction.w < 0.0 {
                direction = -direction;
            }
            // Edges in each ellipse's own (minor, major) coordinates.
            let local =
                |frame: DMat3, e: DVec3| DVec2::new(frame.x_axis.dot(e), frame.y_axis.dot(e));
            let bud_local = DMat2::from_cols(
                local(bud_ellipse.frame, bud_edges[0]),
                local(bud_ellipse.frame, bud_edges[1]),
            );
            let open_local = DMat2::from_cols(
                local(open_ellipse.frame, open_edges[0]),
                local(open_ellipse.frame, open_edges[1]),
            );
            Ok(CellGrowth {
                bud: bud_ellipse,
                open: open_ellipse,
                direction,
                adaxial: open_ellipse.major_radius / bud_ellipse.major_radius,
                abaxial: open_ellipse.minor_radius / bud_ellipse.minor_radius,
                in_plane: open_local * bud_local.inverse(),
            })
        })
        .collect()
}
