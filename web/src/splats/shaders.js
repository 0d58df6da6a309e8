// @ts-check
/**
 * GLSL of the splat renderer (seed 002 without an A-buffer): every splat is
 * an instanced quad in its own plane, so the interpolated position on the
 * quad is the eye ray's intersection with the disc, and the quad's
 * coordinates say how far from the centre it is (outside the unit circle:
 * not on the disc). Three passes share the vertex shader:
 *
 * - depth: the nearest disc fragment per pixel and its surface id;
 * - accumulate: additive colour × w and normal × w of the fragments within a
 *   depth tolerance of the front one (and, with surface ids on, of the front
 *   surface only), w falling off with the distance from the splat's centre;
 * - shade: a full-screen triangle divides by Σw and lights (Phong).
 *
 * Each disc fragment is clipped against its partner planes first (packed as
 * codec/points/src/splat/clip.rs documents: one word per splat, RGBA32F
 * planes in a texture).
 */

const SPLAT_VERTEX = `#version 300 es
precision highp float;
precision highp int;
layout(location = 0) in vec2 a_corner;
layout(location = 1) in vec3 a_centre;
layout(location = 2) in vec3 a_normal;
layout(location = 3) in vec3 a_colour;
layout(location = 4) in float a_radius;
layout(location = 5) in uint a_surface;
layout(location = 6) in uint a_clip;
uniform mat4 u_view;
uniform mat4 u_projection;
uniform mat3 u_model;
uniform float u_scale;
out vec2 v_local;
out vec3 v_world;
out vec3 v_eye;
out vec3 v_normal;
out vec3 v_colour;
out float v_radius;
flat out uint v_surface;
flat out uint v_clip;
void main() {
  vec3 n = normalize(a_normal);
  vec3 a = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
  vec3 t = normalize(cross(n, a));
  vec3 b = cross(n, t);
  float r = a_radius * u_scale;
  vec3 world = a_centre + r * (a_corner.x * t + a_corner.y * b);
  v_local = a_corner;
  // Clipping happens in model coordinates (the planes'), the rest upright.
  v_world = world;
  vec3 upright = u_model * world;
  v_eye = (u_view * vec4(upright, 1.0)).xyz;
  v_normal = mat3(u_view) * (u_model * n);
  v_colour = a_colour;
  v_radius = r;
  v_surface = a_surface;
  v_clip = a_clip;
  gl_Position = u_projection * vec4(v_eye, 1.0);
}`;

/** Shared by the two disc passes: on the disc, and not clipped away. */
const DISC = `
uniform highp sampler2D u_planes;
uniform bool u_clipping;
in vec2 v_local;
in vec3 v_world;
in vec3 v_eye;
in vec3 v_normal;
in vec3 v_colour;
in float v_radius;
flat in uint v_surface;
flat in uint v_clip;
bool clipped() {
  uint count = v_clip & 15u;
  if (!u_clipping || count == 0u) return false;
  uint mode = (v_clip >> 4) & 3u;
  uint first = v_clip >> 6;
  int width = textureSize(u_planes, 0).x;
  bool any = false;
  bool all = true;
  for (uint k = 0u; k < count; k++) {
    int i = int(first + k);
    vec4 plane = texelFetch(u_planes, ivec2(i % width, i / width), 0);
    bool out_ = dot(plane.xyz, v_world) + plane.w > 0.0;
    any = any || out_;
    all = all && out_;
  }
  return mode == 2u ? all : any;
}
float disc() {
  float d2 = dot(v_local, v_local);
  if (d2 > 1.0 || clipped()) discard;
  return d2;
}`;

const DEPTH_FRAGMENT = `#version 300 es
precision highp float;
precision highp int;
${DISC}
layout(location = 0) out uint o_surface;
void main() {
  disc();
  o_surface = v_surface;
}`;

const ACCUMULATE_FRAGMENT = `#version 300 es
precision highp float;
precision highp int;
${DISC}
uniform highp sampler2D u_depth;
uniform highp usampler2D u_front;
uniform bool u_surfaceIds;
uniform float u_near;
uniform float u_far;
uniform float u_tolerance;
layout(location = 0) out vec4 o_colour;
layout(location = 1) out vec4 o_normal;
float linear(float d) {
  return u_near * u_far / (u_far - d * (u_far - u_near));
}
void main() {
  float d2 = disc();
  ivec2 p = ivec2(gl_FragCoord.xy);
  float front = texelFetch(u_depth, p, 0).r;
  if (linear(gl_FragCoord.z) - linear(front) > u_tolerance * v_radius) discard;
  if (u_surfaceIds && texelFetch(u_front, p, 0).r != v_surface) discard;
  float w = exp(-2.5 * d2);
  vec3 n = normalize(v_normal);
  // Normals of a cloud need not agree in orientation: each faces the eye.
  if (dot(n, v_eye) > 0.0) n = -n;
  o_colour = vec4(v_colour * w, w);
  o_normal = vec4(n * w, 0.0);
}`;

const SHADE_VERTEX = `#version 300 es
void main() {
  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}`;

const SHADE_FRAGMENT = `#version 300 es
precision highp float;
uniform sampler2D u_colour;
uniform sampler2D u_normal;
uniform highp sampler2D u_depth;
uniform mat4 u_inverseProjection;
uniform vec2 u_size;
uniform vec3 u_background;
out vec4 o_colour;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec4 c = texelFetch(u_colour, p, 0);
  if (c.a <= 0.0) {
    o_colour = vec4(u_background, 1.0);
    return;
  }
  vec3 albedo = c.rgb / c.a;
  vec3 n = texelFetch(u_normal, p, 0).xyz;
  float depth = texelFetch(u_depth, p, 0).r;
  vec4 ndc = vec4(gl_FragCoord.xy / u_size * 2.0 - 1.0, depth * 2.0 - 1.0, 1.0);
  vec4 view = u_inverseProjection * ndc;
  vec3 position = view.xyz / view.w;
  vec3 toEye = normalize(-position);
  n = length(n) > 0.0 ? normalize(n) : toEye;
  if (dot(n, toEye) < 0.0) n = -n;
  // A headlight a little above and left of the eye.
  vec3 toLight = normalize(vec3(-0.3, 0.5, 1.0));
  float diffuse = max(dot(n, toLight), 0.0);
  vec3 h = normalize(toLight + toEye);
  float specular = pow(max(dot(n, h), 0.0), 40.0) * 0.25;
  vec3 lit = albedo * (0.25 + 0.75 * diffuse) + vec3(specular);
  o_colour = vec4(lit, 1.0);
}`;

export const SHADERS = {
  splat: SPLAT_VERTEX,
  depth: DEPTH_FRAGMENT,
  accumulate: ACCUMULATE_FRAGMENT,
  shadeVertex: SHADE_VERTEX,
  shade: SHADE_FRAGMENT,
};
