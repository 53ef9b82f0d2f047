// nanohaptics play: the camera. An orbit camera around a target (yaw, pitch, distance), the
// canvas's size, and the projection of world points (display metres) to canvas pixels.

import { $ } from './page.js';

export const canvas = $('view');
export const cam = { yaw: -Math.PI / 2, pitch: 0.55, dist: 14, target: [0, 0, 0], fov: 0.9 };

// The canvas in CSS pixels and the device pixel ratio (set by resize()).
export let W = 1, H = 1, dpr = 1;

export function resize() {
  dpr = window.devicePixelRatio || 1;
  const r = canvas.getBoundingClientRect();
  W = Math.max(1, r.width); H = Math.max(1, r.height);
  canvas.width = Math.round(W * dpr); canvas.height = Math.round(H * dpr);
}

function basis() {
  const cp = Math.cos(cam.pitch), sp = Math.sin(cam.pitch), cy = Math.cos(cam.yaw), sy = Math.sin(cam.yaw);
  const back = [cp * cy, cp * sy, sp];
  const eye = [cam.target[0] + cam.dist * back[0], cam.target[1] + cam.dist * back[1], cam.target[2] + cam.dist * back[2]];
  const right = [-sy, cy, 0];
  const up = [-sp * cy, -sp * sy, cp];
  return { eye, back, right, up, f: (H / 2) / Math.tan(cam.fov / 2) };
}

// The view's basis for this drawing (eye, axes, focal length in pixels): set by aimBasis().
export let B = null;
export function aimBasis() { B = basis(); }

// A world point (display metres) to [x px, y px, depth].
export function project(p) {
  const d = [p[0] - B.eye[0], p[1] - B.eye[1], p[2] - B.eye[2]];
  const z = -(d[0] * B.back[0] + d[1] * B.back[1] + d[2] * B.back[2]);
  const x = d[0] * B.right[0] + d[1] * B.right[1] + d[2] * B.right[2];
  const y = d[0] * B.up[0] + d[1] * B.up[1] + d[2] * B.up[2];
  const zz = Math.max(z, 1e-3);
  return [W / 2 + B.f * x / zz, H / 2 - B.f * y / zz, z];
}

// Rotates v by the unit quaternion q = [x, y, z, w].
export function qrot(q, v) {
  const [x, y, z, w] = q;
  const tx = 2 * (y * v[2] - z * v[1]), ty = 2 * (z * v[0] - x * v[2]), tz = 2 * (x * v[1] - y * v[0]);
  return [v[0] + w * tx + (y * tz - z * ty), v[1] + w * ty + (z * tx - x * tz), v[2] + w * tz + (x * ty - y * tx)];
}

// Screen right and away (in the ground plane) as device x, y.
export function horiz(u, v) {
  const cy = Math.cos(cam.yaw), sy = Math.sin(cam.yaw);
  return [u * -sy + v * -cy, u * cy + v * -sy];
}

// Aims the camera at the device workspace of a hello message.
export function aimAtWorkspace(h) {
  const ws_m = h.workspace_radius_m * h.mapping.workspace_scale * h.display_scale;
  cam.target = h.mapping.origin_m.map((x) => x * h.display_scale);
  cam.target[2] = Math.min(cam.target[2], ws_m * 0.15);
  cam.dist = ws_m * 1.35;
}
