// Lit, two-sided flower organs and the viewport background with a soft
// ground shadow under the flower.
//
// Used by `anthesis-render` (crates/render/src/pipeline.rs); the uniform
// structs below must match `FrameUniform` and `OrganUniform` there byte for
// byte.
//
// Conventions:
// - world frame: flower axis +Y (the hemisphere light's sky is +Y);
// - a mesh normal points to the organ's inner side; the side the normal
//   points at is the "front" (counter-clockwise winding seen from it);
// - depth is reversed (near = 1, infinitely far = 0), compare GreaterEqual;
// - colours in the uniforms are linear, except the background colours,
//   which are sRGB-encoded and blended in sRGB so the gradient looks even.

struct Frame {
    view_projection: mat4x4<f32>,
    // xyz: the camera position in world space; w unused.
    eye_in_world: vec4<f32>,
    // xyz: unit vector towards the key light, which sits near the camera
    // (a headlight offset up and to the left so curvature reads); w unused.
    light_direction_in_world: vec4<f32>,
    // sRGB-encoded background colours at the top and bottom of the image.
    background_top_srgb: vec4<f32>,
    background_bottom_srgb: vec4<f32>,
    // x: 1 when the colour target is not an sRGB format, so the shader must
    // encode its output itself; 0 when the hardware encodes (…Srgb formats).
    // y: brightness of the back (outer) side relative to the front side.
    // zw: unused.
    output_flags: vec4<f32>,
    // The inverse of view_projection: the background finds the world ray
    // through each pixel with it.
    inverse_view_projection: mat4x4<f32>,
    // The ground under the flower: xz the flower's centre, y the ground's
    // height (world), w the flower's radius around its centre (0: no
    // ground shadow).
    ground: vec4<f32>,
}

struct Organ {
    // Linear RGB; alpha is written but blending is off.
    colour_linear: vec4<f32>,
    // x: how much the per-vertex overlay ramp replaces the organ colour
    // (0 = overlay off, 1 = overlay only). y: 1 when the texture holds the
    // two sides, the inner (front) side on its left half and the outer
    // (back) side on its right half. zw: unused.
    overlay_mix: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(0) var<uniform> organ: Organ;
// The organ's colour over its UVs (a template's baked colour map; 1x1
// white when it has none), multiplied with organ.color_linear. An sRGB
// texture, so samples are linear. Row 0 is the top (v near 1).
@group(2) @binding(0) var colour_texture: texture_2d<f32>;
@group(2) @binding(1) var colour_sampler: sampler;

struct VertexIn {
    @location(0) position_in_world: vec3<f32>,
    @location(1) normal_in_world: vec3<f32>,
    // A scalar map value per vertex, expected in [0, 1].
    @location(2) overlay: f32,
    // The vertex's UV (v = 0 at the organ's base).
    @location(3) uv: vec2<f32>,
}

struct VertexOut {
    @builtin(position) position_in_clip: vec4<f32>,
    @location(0) position_in_world: vec3<f32>,
    @location(1) normal_in_world: vec3<f32>,
    @location(2) overlay: f32,
    @location(3) uv: vec2<f32>,
}

@vertex
fn vs_organ(in: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.position_in_clip = frame.view_projection * vec4<f32>(in.position_in_world, 1.0);
    out.position_in_world = in.position_in_world;
    out.normal_in_world = in.normal_in_world;
    out.overlay = in.overlay;
    out.uv = in.uv;
    return out;
}

// Blue (low) through pale yellow (middle) to red (high), linear RGB. The
// stops RAMP_LOW, RAMP_MIDDLE and RAMP_HIGH are written before this file
// from `anthesis_render::OVERLAY_RAMP_LINEAR` (the one definition, which
// the app's canvas and legend use too).
fn overlay_ramp(value: f32) -> vec3<f32> {
    let t = clamp(value, 0.0, 1.0);
    if t < 0.5 {
        return mix(RAMP_LOW, RAMP_MIDDLE, t * 2.0);
    }
    return mix(RAMP_MIDDLE, RAMP_HIGH, t * 2.0 - 1.0);
}

fn linear_to_srgb(linear: vec3<f32>) -> vec3<f32> {
    let c = clamp(linear, vec3<f32>(0.0), vec3<f32>(1.0));
    let low = c * 12.92;
    let high = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(high, low, c <= vec3<f32>(0.0031308));
}

fn srgb_to_linear(encoded: vec3<f32>) -> vec3<f32> {
    let c = clamp(encoded, vec3<f32>(0.0), vec3<f32>(1.0));
    let low = c / 12.92;
    let high = pow((c + 0.055) / 1.055, vec3<f32>(2.4));
    return select(high, low, c <= vec3<f32>(0.04045));
}

// Turns a linear colour into what the colour target expects.
fn to_target(linear: vec3<f32>) -> vec3<f32> {
    if frame.output_flags.x > 0.5 {
        return linear_to_srgb(linear);
    }
    return linear;
}

// Petal tissue: thin, pale and translucent. Both sides are lit alike
// (each with its own normal); light that reaches the other side shows
// through, tinted by the tissue, so a side turned from the light glows
// in the petal's colour instead of going dark and muddy.
@fragment
fn fs_organ(in: VertexOut, @builtin(front_facing) is_front: bool) -> @location(0) vec4<f32> {
    // Sampled first, in uniform control flow: the whole texture, and each
    // half of a two-sided one (kept half a texel inside its half, so
    // bilinear filtering does not mix the sides).
    let v = 1.0 - in.uv.y;
    let whole = textureSample(colour_texture, colour_sampler, vec2<f32>(in.uv.x, v));
    let half_texel = 0.5 / f32(textureDimensions(colour_texture).x);
    let u_half = clamp(0.5 * in.uv.x, half_texel, 0.5 - half_texel);
    let inner = textureSample(colour_texture, colour_sampler, vec2<f32>(u_half, v));
    let outer = textureSample(colour_texture, colour_sampler, vec2<f32>(u_half + 0.5, v));
    var painted = whole;
    if organ.overlay_mix.y > 0.5 {
        painted = select(outer, inner, is_front);
    }
    var normal = normalize(in.normal_in_world);
    var side_brightness = 1.0;
    if !is_front {
        // The back (outer) side: shade with the flipped normal, a little
        // less bright.
        normal = -normal;
        side_brightness = frame.output_flags.y;
    }
    let to_eye = normalize(frame.eye_in_world.xyz - in.position_in_world);

    // Key light: a directional light from near the camera, wrapped so the
    // light falls off softly towards the silhouette.
    let light = frame.light_direction_in_world.xyz;
    let wrap = 0.4;
    let key = max((dot(normal, light) + wrap) / (1.0 + wrap), 0.0);
    // Light through the tissue from the other side.
    let through = max(dot(-normal, light), 0.0);
    // Hemisphere ambient: sky above (+Y), a neutral pale ground below.
    let sky = vec3<f32>(0.95, 0.97, 1.0);
    let ground = vec3<f32>(0.72, 0.70, 0.68);
    let ambient = mix(ground, sky, 0.5 + 0.5 * normal.y);
    // A faint broad sheen so curvature reads on pale petals.
    let halfway = normalize(light + to_eye);
    let sheen = 0.04 * pow(max(dot(normal, halfway), 0.0), 16.0);

    var base = organ.colour_linear.rgb * painted.rgb;
    base = mix(base, overlay_ramp(in.overlay), clamp(organ.overlay_mix.x, 0.0, 1.0));

    let reflected = base * (0.42 * ambient + 0.6 * key);
    // Transmitted light is filtered by the tissue twice over (its colour
    // squared): more saturated than the reflected colour.
    let transmitted = 0.5 * through * base * base;
    let lit = (reflected + transmitted + vec3<f32>(sheen)) * side_brightness;
    return vec4<f32>(to_target(lit), organ.colour_linear.a * painted.a);
}

struct BackgroundOut {
    @builtin(position) position_in_clip: vec4<f32>,
    // 0 at the top of the image, 1 at the bottom.
    @location(0) down: f32,
    // The pixel in normalised device coordinates (x right, y up).
    @location(1) ndc: vec2<f32>,
}

// A full-screen triangle at the far plane (depth 0 with reversed depth).
@vertex
fn vs_background(@builtin(vertex_index) index: u32) -> BackgroundOut {
    let x = f32((index << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(index & 2u) * 2.0 - 1.0;
    var out: BackgroundOut;
    out.position_in_clip = vec4<f32>(x, y, 0.0, 1.0);
    out.down = 0.5 - 0.5 * y;
    out.ndc = vec2<f32>(x, y);
    return out;
}

// How dark the ground shadow is at its centre (a fraction of the
// background's brightness taken away).
const GROUND_SHADOW_STRENGTH: f32 = 0.38;

// The soft shadow the flower casts on the ground under it, as seen through
// the pixel at `ndc`: 0 (none) to GROUND_SHADOW_STRENGTH. The ground is the
// plane y = ground.y; the shadow a disc about the flower's radius, fading
// out towards its rim.
fn ground_shadow(ndc: vec2<f32>) -> f32 {
    let radius = frame.ground.w;
    if radius <= 0.0 {
        return 0.0;
    }
    // Two points on the pixel's ray (reversed depth: 1 is the near plane).
    let near = frame.inverse_view_projection * vec4<f32>(ndc, 1.0, 1.0);
    let middle = frame.inverse_view_projection * vec4<f32>(ndc, 0.5, 1.0);
    let origin = near.xyz / near.w;
    let direction = middle.xyz / middle.w - origin;
    if abs(direction.y) < 1e-12 {
        return 0.0;
    }
    let t = (frame.ground.y - origin.y) / direction.y;
    if t <= 0.0 {
        return 0.0;
    }
    let hit = origin + t * direction;
    let distance = length(hit.xz - frame.ground.xz) / radius;
    return GROUND_SHADOW_STRENGTH * (1.0 - smoothstep(0.15, 1.15, distance));
}

@fragment
fn fs_background(in: BackgroundOut) -> @location(0) vec4<f32> {
    let gradient = mix(frame.background_top_srgb.rgb, frame.background_bottom_srgb.rgb, clamp(in.down, 0.0, 1.0));
    let srgb = gradient * (1.0 - ground_shadow(in.ndc));
    var out = srgb;
    if frame.output_flags.x < 0.5 {
        // The target encodes to sRGB itself: hand it linear values.
        out = srgb_to_linear(srgb);
    }
    return vec4<f32>(out, 1.0);
}
