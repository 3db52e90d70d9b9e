// Marched slices, for adapters with compute shaders: the very slices vs_main and fs_main draw
// (the same planes, the same light at each point), composited per pixel in a compute pass
// instead of rasterised and blended. A compute card runs fragment shaders on a few of its
// multiprocessors and compute on all of them; and a pixel's ray can stop where the cloud in
// front already hides what is behind, which blending cannot.
//
// Each invocation walks its pixel's ray front to back through this draw's slices where the ray
// is inside the grid's box (its planes: slice_depth), with the shafts' shells among them in the
// order vs_main merges them, and stops once what it has passed lets less than `HIDDEN` through.
// It writes the draw's premultiplied image, and into the second target the shafts' light with
// the slices' opacity, as fs_shafts's two targets hold them; march_blend.wgsl then lays both
// over the accumulation targets with the slices' own "over" blending, so refinement's chunks
// and the composite work as with the rasterised slices.
// Composed after volume_common.wgsl, volume_noise.wgsl, sun_shadow.wgsl and volume.wgsl.

@group(1) @binding(0) var cloud_out: texture_storage_2d<rgba16float, write>;
@group(1) @binding(1) var shafts_out: texture_storage_2d<rgba16float, write>;

// Transmittance below which a ray stops: what lies behind could change the pixel by less than
// this share of its light (under half a step of an 8-bit channel).
const HIDDEN: f32 = 1.0 / 1024.0;

// The ray's stretch inside the grid's box (entry and exit distances from `a` along `dir`);
// empty (entry > exit) where it misses.
fn box_stretch(a: vec3<f32>, dir: vec3<f32>) -> vec2<f32> {
    let lo = u.grid_min.xyz;
    let hi = lo + 1.0 / u.grid_inv_size.xyz;
    // A direction component of zero: the slab is all or nothing, as a huge inverse gives.
    let d = select(dir, vec3<f32>(1e-12), abs(dir) < vec3<f32>(1e-12));
    let t0 = (lo - a) / d;
    let t1 = (hi - a) / d;
    let near = min(t0, t1);
    let far = max(t0, t1);
    return vec2<f32>(max(max(near.x, near.y), near.z), min(min(far.x, far.y), far.z));
}

// 8 × 8 pixels a workgroup (MARCH_WORKGROUP in src/render/passes.rs).
@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(cloud_out);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    // The pixel's ray, as the fragments of a slice see it: from its point on the near plane
    // to its point on the far plane.
    let pixel = vec2<f32>(id.xy) + 0.5;
    let ndc = vec2<f32>(pixel.x / f32(size.x) * 2.0 - 1.0, 1.0 - pixel.y / f32(size.y) * 2.0);
    let near = u.inv_view_proj * vec4<f32>(ndc, 0.0, 1.0);
    let far = u.inv_view_proj * vec4<f32>(ndc, 1.0, 1.0);
    let a = near.xyz / near.w;
    let b = far.xyz / far.w;
    let dir = normalize(b - a);
    let n = u.forward.xyz;
    let along = max(dot(dir, n), 1e-6);
    let spacing = u.slicing.z;
    // Depth along the view of the ray's start, from the bounding sphere's centre (the slices'
    // origin): slice j's plane lies at grid_min.w − (j + 0.5) · spacing.
    let start = dot(a - u.sphere.xyz, n);
    // The slices this ray meets inside the box (one more each side: the box test of cloud_at
    // is exact), of this draw's.
    let first = i32(u.slicing.y);
    let last = first + i32(u.shells.z) - 1;
    let stretch = box_stretch(a, dir);
    let enter = max(stretch.x, 0.0);
    let exit = min(stretch.y, length(b - a));
    var nearest = first - 1;
    var farthest = first;
    if enter <= exit {
        let j_enter = (u.grid_min.w - start - enter * along) / spacing - 0.5;
        let j_exit = (u.grid_min.w - start - exit * along) / spacing - 0.5;
        nearest = min(i32(floor(j_enter)) + 1, last);
        farthest = max(i32(ceil(j_exit)) - 1, first);
    }
    // Shells of this draw, nearest first.
    let shell_first = i32(u.shells.x);
    var k = shell_first + i32(u.shells.y) - 1;
    var light = vec3<f32>(0.0);
    var shafts = vec3<f32>(0.0);
    var through = 1.0;
    for (var j = nearest; j >= farthest; j = j - 1) {
        let depth = u.grid_min.w - (f32(j) + 0.5) * spacing;
        if u.shells.y > 0.0 {
            // The shells nearer than this slice (vs_main puts them after it, back to front).
            let beyond = clamp(shells_beyond(slice_depth(f32(j))), shell_first, k + 1);
            for (; k >= beyond; k = k - 1) {
                shafts = shafts + through * shaft(a, b, pixel, k);
            }
        }
        let c = cloud_at(a + dir * ((depth - start) / along));
        light = light + through * c.rgb;
        through = through * (1.0 - c.a);
        if through < HIDDEN {
            break;
        }
    }
    if through >= HIDDEN {
        for (; k >= shell_first; k = k - 1) {
            shafts = shafts + through * shaft(a, b, pixel, k);
        }
    }
    // Laid into the accumulation as the slices draw into it: at its light scale.
    textureStore(cloud_out, id.xy, accumulated(vec4<f32>(light, 1.0 - through)));
    textureStore(shafts_out, id.xy, vec4<f32>(shafts, 1.0 - through));
}
