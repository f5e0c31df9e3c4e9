// Copies the viewport's offscreen image into egui's render pass
// (anthesis-render's BlitPipeline, used by app/src/desktop/viewport/gpu.rs).
// egui sets the pass viewport to the widget's rectangle, so a full-screen
// triangle covers exactly the widget.
//
// The offscreen image is `Rgba8Unorm` holding sRGB-encoded colours (the
// organ shader encodes them itself). `fs_blit_encoded` passes them on to a
// non-sRGB target (what egui usually draws into); `fs_blit_decoded` hands
// linear values to an sRGB target, which encodes them again.

@group(0) @binding(0) var image: texture_2d<f32>;
@group(0) @binding(1) var image_sampler: sampler;

struct BlitOut {
    @builtin(position) position_in_clip: vec4<f32>,
    // (0, 0) at the top left of the image.
    @location(0) point_in_image: vec2<f32>,
}

@vertex
fn vs_blit(@builtin(vertex_index) index: u32) -> BlitOut {
    let x = f32((index << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(index & 2u) * 2.0 - 1.0;
    var out: BlitOut;
    out.position_in_clip = vec4<f32>(x, y, 0.0, 1.0);
    out.point_in_image = vec2<f32>(0.5 + 0.5 * x, 0.5 - 0.5 * y);
    return out;
}

@fragment
fn fs_blit_encoded(in: BlitOut) -> @location(0) vec4<f32> {
    return vec4<f32>(textureSample(image, image_sampler, in.point_in_image).rgb, 1.0);
}

fn srgb_to_linear(encoded: vec3<f32>) -> vec3<f32> {
    let c = clamp(encoded, vec3<f32>(0.0), vec3<f32>(1.0));
    let low = c / 12.92;
    let high = pow((c + 0.055) / 1.055, vec3<f32>(2.4));
    return select(high, low, c <= vec3<f32>(0.04045));
}

@fragment
fn fs_blit_decoded(in: BlitOut) -> @location(0) vec4<f32> {
    let encoded = textureSample(image, image_sampler, in.point_in_image).rgb;
    return vec4<f32>(srgb_to_linear(encoded), 1.0);
}
