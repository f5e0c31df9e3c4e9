use std::sync::Arc;

use glam::DVec3;

/// One organ ready to draw: `f32` world-space vertices with normals, its
/// triangles and a colour, optionally painted by a texture over its UVs
/// (a template's colour map, baked).
///
/// Normals point to the organ's inner side (the Anthesis winding
/// convention); the side they point at is shaded as the front, the other
/// side slightly darker.
#[derive(Debug, Clone, PartialEq)]
pub struct OrganMesh {
    /// Vertex positions in world space.
    pub positions_in_world: Vec<[f32; 3]>,
    /// Unit vertex normals in world space, one per position.
    pub normals_in_world: Vec<[f32; 3]>,
    /// Vertex indices, three per triangle.
    pub triangles: Vec<[u32; 3]>,
    /// Linear RGBA in `[0, 1]`, as project files and exports hold colours;
    /// the renderer encodes for the target once, at the end of its shader.
    pub colour_linear: [f32; 4],
    /// An optional scalar per vertex in `[0, 1]` (e.g. a growth-map value)
    /// shown with a blue–yellow–red ramp instead of the organ colour.
    pub overlay: Option<Vec<f32>>,
    /// An optional colour texture multiplied with `color_linear`: its
    /// texture coordinate per vertex and an 8-bit sRGB-encoded RGBA image
    /// whose bottom row is `v = 0` (as map images and
    /// `Template::colour_image` are). `None` draws as a 1x1 white texture
    /// would: `color_linear` alone. The renderer keeps the image uploaded
    /// while the same `Arc` comes back.
    pub texture: Option<OrganTexture>,
}

/// A colour texture over an organ's UVs (see [`OrganMesh::texture`]).
#[derive(Debug, Clone, PartialEq)]
pub struct OrganTexture {
    /// One `[u, v]` per vertex (`v = 0` at the organ's base).
    pub uvs: Vec<[f32; 2]>,
    /// 8-bit sRGB-encoded RGBA, row 0 at the top (`v` near 1).
    pub image: Arc<image::RgbaImage>,
    /// The image holds both sides: the inner side (the front, which the
    /// normals point to) on its left half, the outer side on its right
    /// half (`Template::colour_atlas`).
    pub two_sided: bool,
}

impl OrganMesh {
    /// Builds a mesh from `f64` world positions, computing area-weighted
    /// vertex normals from the triangles' winding.
    pub fn from_positions(
        positions_in_world: &[DVec3],
        triangles: &[[u32; 3]],
        colour_linear: [f32; 4],
    ) -> OrganMesh {
        let normals = anthesis_mesh::vertex_normals(positions_in_world, triangles);
        OrganMesh {
            positions_in_world: positions_in_world
                .iter()
                .map(|p| p.as_vec3().to_array())
                .collect(),
            normals_in_world: normals.iter().map(|n| n.as_vec3().to_array()).collect(),
            triangles: triangles.to_vec(),
            colour_linear,
            overlay: None,
            texture: None,
        }
    }

    /// Paints the organ with `image` over its `uvs` (one per vertex),
    /// multiplied with its colour (so use white to show the image as it
    /// is).
    pub fn with_texture(mut self, uvs: Vec<[f32; 2]>, image: Arc<image::RgbaImage>) -> OrganMesh {
        self.texture = Some(OrganTexture {
            uvs,
            image,
            two_sided: false,
        });
        self
    }

    /// Paints the organ's two sides differently: `atlas` holds the inner
    /// side's image on its left half and the outer side's on its right
    /// (see [`OrganTexture::two_sided`]).
    pub fn with_two_sided_texture(
        mut self,
        uvs: Vec<[f32; 2]>,
        atlas: Arc<image::RgbaImage>,
    ) -> OrganMesh {
        self.texture = Some(OrganTexture {
            uvs,
            image: atlas,
            two_sided: true,
        });
        self
    }

    /// Adds a per-vertex overlay (values in `[0, 1]`).
    pub fn with_overlay(mut self, overlay: Vec<f32>) -> OrganMesh {
        self.overlay = Some(overlay);
        self
    }

    /// The axis-aligned bounds of the positions, `None` when there are none.
    pub fn bounds_in_world(&self) -> Option<(DVec3, DVec3)> {
        organs_bounds_in_world(std::slice::from_ref(self))
    }

    /// Checks the array lengths and triangle indices; the message names the
    /// first problem.
    pub fn check(&self) -> Result<(), String> {
        let n = self.positions_in_world.len();
        if self.normals_in_world.len() != n {
            return Err(format!(
                "{} normals for {n} positions",
                self.normals_in_world.len()
            ));
        }
        if let Some(overlay) = &self.overlay
            && overlay.len() != n
        {
            return Err(format!(
                "{} overlay values for {n} positions",
                overlay.len()
            ));
        }
        if let Some(texture) = &self.texture {
            if texture.uvs.len() != n {
                return Err(format!(
                    "{} texture coordinates for {n} positions",
                    texture.uvs.len()
                ));
            }
            if texture.image.width() == 0 || texture.image.height() == 0 {
                return Err("the texture image is empty".to_string());
            }
        }
        if n > u32::MAX as usize {
            return Err(format!("{n} vertices do not fit u32 indices"));
        }
        for (t, tri) in self.triangles.iter().enumerate() {
            if let Some(&i) = tri.iter().find(|&&i| i as usize >= n) {
                return Err(format!(
                    "triangle {t} uses vertex {i} but there are only {n} vertices"
                ));
            }
        }
        Ok(())
    }
}

/// The axis-aligned bounds of all organs' positions, `None` when empty.
pub fn organs_bounds_in_world(organs: &[OrganMesh]) -> Option<(DVec3, DVec3)> {
    let mut points = organs
        .iter()
        .flat_map(|o| o.positions_in_world.iter())
        .map(|p| DVec3::new(p[0].into(), p[1].into(), p[2].into()));
    let first = points.next()?;
    Some(points.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
}
