// nanohaptics play: drawing. A frame's shapes (the server's `prims`, short keys: `k` kind,
// `c` centre, `r` radius, `h` half extents, `q` quaternion, `ax` semi-axes, `p` points,
// `a`/`b` arrow tail/head, `col` RGBA 0–1; all in world metres) painted on the Canvas 2D
// with a painter's sort, in colours colour-blind players tell apart.

import { P } from './page.js';
import { canvas, B, W, H, dpr, aimBasis, project, qrot } from './camera.js';

const g = canvas.getContext('2d');

// Okabe–Ito: colours that colour-blind players tell apart.
const OKABE = [[0, 0, 0], [230, 159, 0], [86, 180, 233], [0, 158, 115], [240, 228, 66],
  [0, 114, 178], [213, 94, 0], [204, 121, 167], [200, 205, 210]];
const palette = new Map();
function safeColour(c) {
  const key = c.slice(0, 3).join(',');
  let rgb = palette.get(key);
  if (!rgb) {
    const [r, gg, b] = c.map((x) => x * 255);
    const mx = Math.max(r, gg, b), mn = Math.min(r, gg, b);
    if (mx - mn < 40) {
      rgb = [r, gg, b].map(Math.round); // greys and white stay
    } else {
      let best = 1e9;
      for (const o of OKABE.slice(1, 8)) {
        // Nearest by hue, weighted with lightness.
        const d = hueDist(hue(r, gg, b), hue(...o)) * 2 + Math.abs(mx - Math.max(...o)) / 255;
        if (d < best) { best = d; rgb = o; }
      }
    }
    palette.set(key, rgb);
  }
  return rgb;
}
function hue(r, gg, b) {
  const mx = Math.max(r, gg, b), mn = Math.min(r, gg, b), d = mx - mn || 1;
  let h = mx === r ? (gg - b) / d : mx === gg ? 2 + (b - r) / d : 4 + (r - gg) / d;
  return ((h * 60) + 360) % 360;
}
function hueDist(a, b) { const d = Math.abs(a - b) % 360; return Math.min(d, 360 - d) / 180; }
function css(c, shade, alpha) {
  const rgb = safeColour(c);
  const s = shade === undefined ? 1 : shade;
  const a = alpha === undefined ? c[3] : alpha;
  return `rgba(${Math.round(rgb[0] * s)},${Math.round(rgb[1] * s)},${Math.round(rgb[2] * s)},${a})`;
}

const LIGHT = (() => { const l = [0.4, -0.5, 0.77]; const n = Math.hypot(...l); return l.map((x) => x / n); })();
function boxGeometry(p, s) {
  const c = p.c.map((x) => x * s), h = p.h.map((x) => x * s), q = p.q;
  const corners = [];
  for (let i = 0; i < 8; i++) {
    const v = [(i & 1 ? 1 : -1) * h[0], (i & 2 ? 1 : -1) * h[1], (i & 4 ? 1 : -1) * h[2]];
    const r = qrot(q, v);
    corners.push([c[0] + r[0], c[1] + r[1], c[2] + r[2]]);
  }
  return corners;
}
const FACES = [[0, 2, 6, 4, [-1, 0, 0]], [1, 5, 7, 3, [1, 0, 0]], [0, 4, 5, 1, [0, -1, 0]],
  [2, 3, 7, 6, [0, 1, 0]], [0, 1, 3, 2, [0, 0, -1]], [4, 6, 7, 5, [0, 0, 1]]];
const EDGES = [[0, 1], [2, 3], [4, 5], [6, 7], [0, 2], [1, 3], [4, 6], [5, 7], [0, 4], [1, 5], [2, 6], [3, 7]];

// Paints frame `f` (a `frame` message with its drawing) at the hello `hello`'s display scale;
// `gripping`: the hand grips (its ring turns orange).
export function draw(f, hello, gripping) {
  g.setTransform(dpr, 0, 0, dpr, 0, 0);
  const grd = g.createLinearGradient(0, 0, 0, H);
  grd.addColorStop(0, '#26303b'); grd.addColorStop(1, '#12161b');
  g.fillStyle = grd; g.fillRect(0, 0, W, H);
  if (!f || !f.prims || !hello) return;
  aimBasis();
  const s = hello.display_scale;
  const items = [];
  const labels = [];
  f.prims.forEach((p, idx) => {
    // The scenes draw their ground (or substrate) first: it is the background, drawn before
    // everything (a painter's sort by face centre would put it over what stands far on it).
    const ground = idx === 0 && p.k === 'box';
    if (p.k === 'box' || p.k === 'slot') {
      const cs = boxGeometry(p, s);
      const pr = cs.map(project);
      if (p.k === 'slot' || p.col[3] < 0.5) {
        const z = pr.reduce((a, v) => a + v[2], 0) / 8;
        items.push({ z: z - 1e-3, fn: () => {
          g.setLineDash([6, 4]); g.lineWidth = 2; g.strokeStyle = css(p.col, 1, 1);
          g.fillStyle = css(p.col, 1, 0.18);
          for (const fc of FACES) {
            const n = qrot(p.q, fc[4]);
            const c = cs[fc[0]];
            if ((c[0] - B.eye[0]) * n[0] + (c[1] - B.eye[1]) * n[1] + (c[2] - B.eye[2]) * n[2] < 0) {
              g.beginPath(); for (let k = 0; k < 4; k++) { const v = pr[fc[k]]; k ? g.lineTo(v[0], v[1]) : g.moveTo(v[0], v[1]); }
              g.closePath(); g.fill();
            }
          }
          g.beginPath(); for (const [a, b] of EDGES) { g.moveTo(pr[a][0], pr[a][1]); g.lineTo(pr[b][0], pr[b][1]); }
          g.stroke(); g.setLineDash([]);
        } });
        return;
      }
      for (const fc of FACES) {
        const n = qrot(p.q, fc[4]);
        const c = cs[fc[0]];
        if ((c[0] - B.eye[0]) * n[0] + (c[1] - B.eye[1]) * n[1] + (c[2] - B.eye[2]) * n[2] >= 0) continue;
        const z = (pr[fc[0]][2] + pr[fc[1]][2] + pr[fc[2]][2] + pr[fc[3]][2]) / 4;
        const shade = 0.45 + 0.55 * Math.max(0, n[0] * LIGHT[0] + n[1] * LIGHT[1] + n[2] * LIGHT[2]);
        items.push({ z: ground ? Infinity : z, fn: () => {
          g.beginPath(); for (let k = 0; k < 4; k++) { const v = pr[fc[k]]; k ? g.lineTo(v[0], v[1]) : g.moveTo(v[0], v[1]); }
          g.closePath(); g.fillStyle = css(p.col, shade); g.fill();
          g.strokeStyle = 'rgba(0,0,0,0.35)'; g.lineWidth = 1; g.stroke();
        } });
      }
    } else if (p.k === 'sphere' || p.k === 'cursor' || p.k === 'ellipse') {
      const c = p.c.map((x) => x * s);
      const v = project(c);
      const r = Math.max(1.5, B.f * (p.r !== undefined ? p.r : p.ax[0]) * s / Math.max(v[2], 1e-3));
      items.push({ z: v[2], fn: () => {
        const gr = g.createRadialGradient(v[0] - r / 3, v[1] - r / 3, r / 6, v[0], v[1], r);
        gr.addColorStop(0, css(p.col, 1.25)); gr.addColorStop(1, css(p.col, 0.55));
        g.beginPath(); g.arc(v[0], v[1], r, 0, 2 * Math.PI); g.fillStyle = gr; g.fill();
        if (p.k === 'cursor' || p.col[3] < 1) { g.lineWidth = 2; g.strokeStyle = css(p.col, 1, 1); g.stroke(); }
      } });
    } else if (p.k === 'line') {
      const pts = p.p.map((q) => project(q.map((x) => x * s)));
      const z = pts.reduce((a, v) => a + v[2], 0) / Math.max(1, pts.length);
      items.push({ z: -1e9, fn: () => { // outlines on the ground: over the ground, drawn last
        g.beginPath(); pts.forEach((v, k) => (k ? g.lineTo(v[0], v[1]) : g.moveTo(v[0], v[1])));
        if (p.closed) g.closePath();
        g.lineWidth = 2.5; g.strokeStyle = css(p.col, 1, 1); g.setLineDash([10, 6]); g.stroke(); g.setLineDash([]);
      } });
    } else if (p.k === 'arrow') {
      const a = project(p.a.map((x) => x * s)), b = project(p.b.map((x) => x * s));
      labels.push(() => arrow(a, b, p.col));
    } else if (p.k === 'label') {
      labels.push(() => {
        const v = project(p.c.map((x) => x * s));
        g.font = '600 15px system-ui, sans-serif'; g.textAlign = 'center';
        g.fillStyle = 'rgba(0,0,0,0.6)'; g.fillText(p.text, v[0] + 1, v[1] + 1);
        g.fillStyle = css(p.col, 1, 1); g.fillText(p.text, v[0], v[1]);
      });
    }
  });
  if (f.cursor_m) {
    // The hand's height: a line down to the ground and a ring where it meets it.
    const c = f.cursor_m.map((x) => x * s);
    const top = project(c), foot = project([c[0], c[1], 0]);
    items.push({ z: foot[2] - 1e-3, fn: () => {
      g.strokeStyle = 'rgba(86,180,233,0.9)'; g.lineWidth = 1.5; g.setLineDash([3, 3]);
      g.beginPath(); g.moveTo(top[0], top[1]); g.lineTo(foot[0], foot[1]); g.stroke(); g.setLineDash([]);
      g.beginPath(); g.ellipse(foot[0], foot[1], 9, 4, 0, 0, 2 * Math.PI); g.stroke();
    } });
    labels.push(() => {
      g.beginPath(); g.arc(top[0], top[1], 6, 0, 2 * Math.PI);
      g.strokeStyle = gripping ? '#e69f00' : '#56b4e9'; g.lineWidth = 2.5; g.stroke();
    });
  }
  items.sort((a, b) => b.z - a.z);
  for (const it of items) it.fn();
  for (const l of labels) l();
  // The hand: where the page puts it (the server's cursor follows within a tick).
  P.draws++;
}
function arrow(a, b, col) {
  const dx = b[0] - a[0], dy = b[1] - a[1], L = Math.hypot(dx, dy);
  if (L < 2) return;
  g.strokeStyle = css(col, 1, 1); g.fillStyle = g.strokeStyle; g.lineWidth = 4;
  g.beginPath(); g.moveTo(a[0], a[1]); g.lineTo(b[0], b[1]); g.stroke();
  const ux = dx / L, uy = dy / L, hl = Math.min(14, L / 2);
  g.beginPath(); g.moveTo(b[0] + ux * 4, b[1] + uy * 4);
  g.lineTo(b[0] - ux * hl - uy * hl / 2, b[1] - uy * hl + ux * hl / 2);
  g.lineTo(b[0] - ux * hl + uy * hl / 2, b[1] - uy * hl - ux * hl / 2); g.closePath(); g.fill();
}
