// nanohaptics play: the page. Draws the frames the server sends, sends the hand, plays the
// sound blocks. Plain JavaScript, no library. window.__play holds figures for tests/benches.
'use strict';
(function () {
  const $ = (id) => document.getElementById(id);
  const canvas = $('view');
  const g = canvas.getContext('2d');
  const P = (window.__play = {
    hello: null, role: null, frames: 0, draws: 0, drawT0: 0, lastFrame: null,
    events: [], sounds: [], switched: [], errors: [], ended: null,
    pcm: { first: -1, samples: 0, hash: 0x811c9dc5, blocks: 0, underruns: 0, early: 0, rebased: 0 },
    audioLatencyMs: [], audioParts: [], outputLatencyS: null, inputsSent: 0,
  });
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

  // ---- camera -------------------------------------------------------------------------
  const cam = { yaw: -Math.PI / 2, pitch: 0.55, dist: 14, target: [0, 0, 0], fov: 0.9 };
  let W = 1, H = 1, dpr = 1;
  function resize() {
    dpr = window.devicePixelRatio || 1;
    const r = canvas.getBoundingClientRect();
    W = Math.max(1, r.width); H = Math.max(1, r.height);
    canvas.width = Math.round(W * dpr); canvas.height = Math.round(H * dpr);
  }
  window.addEventListener('resize', resize);
  function basis() {
    const cp = Math.cos(cam.pitch), sp = Math.sin(cam.pitch), cy = Math.cos(cam.yaw), sy = Math.sin(cam.yaw);
    const back = [cp * cy, cp * sy, sp];
    const eye = [cam.target[0] + cam.dist * back[0], cam.target[1] + cam.dist * back[1], cam.target[2] + cam.dist * back[2]];
    const right = [-sy, cy, 0];
    const up = [-sp * cy, -sp * sy, cp];
    return { eye, back, right, up, f: (H / 2) / Math.tan(cam.fov / 2) };
  }
  let B = null;
  function project(p) {
    const d = [p[0] - B.eye[0], p[1] - B.eye[1], p[2] - B.eye[2]];
    const z = -(d[0] * B.back[0] + d[1] * B.back[1] + d[2] * B.back[2]);
    const x = d[0] * B.right[0] + d[1] * B.right[1] + d[2] * B.right[2];
    const y = d[0] * B.up[0] + d[1] * B.up[1] + d[2] * B.up[2];
    const zz = Math.max(z, 1e-3);
    return [W / 2 + B.f * x / zz, H / 2 - B.f * y / zz, z];
  }
  function qrot(q, v) {
    const [x, y, z, w] = q;
    const tx = 2 * (y * v[2] - z * v[1]), ty = 2 * (z * v[0] - x * v[2]), tz = 2 * (x * v[1] - y * v[0]);
    return [v[0] + w * tx + (y * tz - z * ty), v[1] + w * ty + (z * tx - x * tz), v[2] + w * tz + (x * ty - y * tx)];
  }

  // ---- drawing ------------------------------------------------------------------------
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
  function draw() {
    const f = P.lastFrame;
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    const grd = g.createLinearGradient(0, 0, 0, H);
    grd.addColorStop(0, '#26303b'); grd.addColorStop(1, '#12161b');
    g.fillStyle = grd; g.fillRect(0, 0, W, H);
    if (!f || !f.prims || !P.hello) return;
    B = basis();
    const s = P.hello.display_scale;
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
        g.strokeStyle = hand.grip || hand.pointerGrip || gpGrip ? '#e69f00' : '#56b4e9'; g.lineWidth = 2.5; g.stroke();
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

  // ---- the hand -----------------------------------------------------------------------
  const hand = { n: [0, 0, 0], grip: false, pointerGrip: false, turn: [false, false, false], dirty: true, seq: 0, lastSent: 0 };
  const held = new Map(); // key → speed factor (Shift: fine moves)
  P.hand = hand;
  function clampBall() {
    const r = Math.hypot(...hand.n);
    if (r > 1) hand.n = hand.n.map((x) => x / r * (1 - 1e-12));
    hand.n = hand.n.map((x) => Math.max(-1, Math.min(1, x)));
  }
  function buttons() {
    let b = (hand.grip || hand.pointerGrip || gpGrip) ? 1 : 0;
    const nb = P.hello ? P.hello.buttons.length : 1;
    for (let i = 0; i < 3; i++) if (hand.turn[i] && i + 1 < nb) b |= 1 << (i + 1);
    return b;
  }
  function send(o) { if (ws && ws.readyState === 1) ws.send(JSON.stringify(o)); }
  function sendHand(tStamp) {
    if (!P.hello || !P.hello.page_is_hand || P.role !== 'hand' || P.ended) return;
    clampBall();
    hand.seq++;
    send({ type: 'input', seq: hand.seq, pos: hand.n, buttons: buttons(), t_ms: performance.timeOrigin + (tStamp || performance.now()) });
    P.inputsSent++;
    hand.dirty = false; hand.lastSent = performance.now();
  }
  function horiz(u, v) {
    // Screen right and away (in the ground plane) as device x, y.
    const cy = Math.cos(cam.yaw), sy = Math.sin(cam.yaw);
    return [u * -sy + v * -cy, u * cy + v * -sy];
  }
  let dragOrbit = null;
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
  canvas.addEventListener('pointerdown', (e) => {
    canvas.focus();
    if (e.button === 2 || e.shiftKey) { dragOrbit = [e.clientX, e.clientY]; return; }
    if (e.button === 0) { hand.pointerGrip = true; pointerTo(e); sendHand(e.timeStamp); }
  });
  window.addEventListener('pointerup', (e) => {
    if (dragOrbit) { dragOrbit = null; return; }
    if (e.button === 0 && hand.pointerGrip) { hand.pointerGrip = false; sendHand(e.timeStamp); }
  });
  function pointerTo(e) {
    const r = canvas.getBoundingClientRect();
    const k = 0.46 * Math.min(r.width, r.height);
    const u = (e.clientX - r.left - r.width / 2) / k, v = -(e.clientY - r.top - r.height / 2) / k;
    const [x, y] = horiz(u, v);
    hand.n[0] = x; hand.n[1] = y;
    const rr = Math.hypot(hand.n[0], hand.n[1], hand.n[2]);
    if (rr > 1) { // keep the height, shrink the plane part
      const m = Math.sqrt(Math.max(0, 1 - hand.n[2] * hand.n[2])) / Math.hypot(hand.n[0], hand.n[1]);
      hand.n[0] *= m; hand.n[1] *= m;
    }
  }
  // pointerrawupdate (where the browser has it) is not held back to the next animation frame
  // as pointermove is: the hand reaches the server up to a frame sooner.
  const MOVE_EVENT = 'onpointerrawupdate' in window ? 'pointerrawupdate' : 'pointermove';
  P.moveEvent = MOVE_EVENT;
  canvas.addEventListener(MOVE_EVENT, (e) => {
    if (dragOrbit) {
      cam.yaw -= (e.clientX - dragOrbit[0]) * 0.01;
      cam.pitch = Math.max(-0.1, Math.min(1.5, cam.pitch + (e.clientY - dragOrbit[1]) * 0.01));
      dragOrbit = [e.clientX, e.clientY];
      return;
    }
    pointerTo(e); sendHand(e.timeStamp);
  });
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    if (e.ctrlKey) { cam.dist *= Math.exp(e.deltaY * 0.002); return; }
    hand.n[2] -= e.deltaY * 0.0015; sendHand(e.timeStamp);
  }, { passive: false });
  const MOVE = { ArrowLeft: [-1, 0, 0], ArrowRight: [1, 0, 0], ArrowUp: [0, 1, 0], ArrowDown: [0, -1, 0], PageUp: [0, 0, 1], PageDown: [0, 0, -1] };
  window.addEventListener('keydown', (e) => {
    if (e.target && (e.target.tagName === 'INPUT' || e.target.tagName === 'BUTTON' || e.target.tagName === 'A')) return;
    const k = e.key;
    if (MOVE[k]) { held.set(k, e.shiftKey ? 0.2 : 1); e.preventDefault(); }
    else if (k === ' ') { if (!e.repeat) { hand.grip = !hand.grip; say(hand.grip ? 'grip on' : 'grip off'); sendHand(e.timeStamp); } e.preventDefault(); }
    else if (k === '1' || k === '2' || k === '3') { hand.turn[+k - 1] = true; sendHand(e.timeStamp); }
    else if (k === 'a' || k === 'A') cam.yaw += 0.08;
    else if (k === 'd' || k === 'D') cam.yaw -= 0.08;
    else if (k === 'w' || k === 'W') cam.pitch = Math.min(1.5, cam.pitch + 0.05);
    else if (k === 's' || k === 'S') cam.pitch = Math.max(-0.1, cam.pitch - 0.05);
    else if (k === '+' || k === '=') cam.dist *= 0.9;
    else if (k === '-') cam.dist /= 0.9;
    else if (k === 'm' || k === 'M') { muted = !muted; if (gain) gain.gain.value = muted ? 0 : 1; say(muted ? 'sound off' : 'sound on'); }
    else if (k === 'e' || k === 'E') { if (!e.repeat) send({ type: 'end' }); }
  });
  window.addEventListener('keyup', (e) => {
    held.delete(e.key);
    if (e.key === '1' || e.key === '2' || e.key === '3') { hand.turn[+e.key - 1] = false; sendHand(e.timeStamp); }
  });
  const KEY_SPEED = 0.5; // unit-ball radii per second
  let gpGrip = false, lastRumble = 0;
  function pollKeysAndPad(dt) {
    let moved = false;
    for (const [k, f] of held) {
      const m = MOVE[k], v = KEY_SPEED * f * dt;
      if (m[2]) { hand.n[2] += m[2] * v; }
      else { const [x, y] = horiz(m[0], m[1]); hand.n[0] += x * v; hand.n[1] += y * v; }
      moved = true;
    }
    const pads = navigator.getGamepads ? navigator.getGamepads() : [];
    for (const gp of pads) {
      if (!gp) continue;
      const dz = (v) => (Math.abs(v) < 0.12 ? 0 : v);
      const [x, y] = horiz(dz(gp.axes[0] || 0), -dz(gp.axes[1] || 0));
      const h = -dz(gp.axes[3] || 0);
      if (x || y || h) { hand.n[0] += x * KEY_SPEED * dt; hand.n[1] += y * KEY_SPEED * dt; hand.n[2] += h * KEY_SPEED * dt; moved = true; }
      const grip = !!(gp.buttons[7] && gp.buttons[7].value > 0.5);
      const turns = [4, 5, 3].map((i) => !!(gp.buttons[i] && gp.buttons[i].pressed));
      if (grip !== gpGrip || turns.some((t, i) => t !== hand.turn[i])) { gpGrip = grip; hand.turn = turns; moved = true; }
      const f = P.lastFrame && P.lastFrame.device_force_n;
      if (gp.vibrationActuator && f && performance.now() - lastRumble > 60) {
        const m = Math.min(1, Math.hypot(...f) / P.hello.max_force_n);
        lastRumble = performance.now();
        if (m > 0.02) gp.vibrationActuator.playEffect('dual-rumble', { duration: 80, strongMagnitude: m, weakMagnitude: m * 0.5 }).catch(() => {});
      }
      break;
    }
    if (moved || performance.now() - hand.lastSent > 100) sendHand();
  }

  // ---- sound --------------------------------------------------------------------------
  let actx = null, gain = null, muted = false, base = null;
  const LEAD_S = 0.02; // jitter buffer: the blocks' arrival jitter on loopback is ~10 ms
  function startAudio() {
    try {
      actx = new AudioContext({ sampleRate: P.hello.sample_rate_hz, latencyHint: 'interactive' });
      gain = actx.createGain(); gain.connect(actx.destination);
      actx.resume();
    } catch (err) { actx = null; say('sound is not available in this browser'); }
  }
  function onPcm(buf) {
    const dv = new DataView(buf);
    const first = Number(dv.getBigUint64(0, true));
    const wallMs = dv.getFloat64(8, true);
    const bytes = new Uint8Array(buf, 16);
    const n = bytes.length / 4;
    const pc = P.pcm;
    if (pc.first < 0) pc.first = first;
    let h = pc.hash;
    for (let i = 0; i < bytes.length; i++) { h ^= bytes[i]; h = Math.imul(h, 0x01000193) >>> 0; }
    pc.hash = h; pc.samples += n; pc.blocks++;
    if (!actx || n === 0) return;
    const sr = P.hello.sample_rate_hz;
    const data = new Float32Array(buf.slice(16));
    const ab = actx.createBuffer(1, n, sr);
    ab.copyToChannel(data, 0);
    if (base === null || base + first / sr < actx.currentTime + 0.005) {
      if (base !== null) pc.underruns++;
      base = actx.currentTime + LEAD_S - first / sr;
    }
    let at = base + first / sr;
    // Blocks that keep arriving early (a late first block, clock drift): come back to the lead.
    const slack = at - actx.currentTime;
    if (slack > LEAD_S + 0.008) {
      if (++pc.early > 20) { base -= slack - LEAD_S; at = base + first / sr; pc.early = 0; pc.rebased++; }
    } else pc.early = 0;
    const src = actx.createBufferSource(); src.buffer = ab; src.connect(gain); src.start(at);
    // Tick to speaker: when this block's first sample leaves the output (the output timestamp
    // maps the context's clock to the page's; it already counts the output device's latency),
    // minus its tick's wall time. Parts: tick → block here, the scheduling lead, and the
    // browser's output pipeline (the rest).
    if (actx.getOutputTimestamp && wallMs > 0) {
      const ts = actx.getOutputTimestamp();
      P.outputLatencyS = actx.outputLatency || 0;
      if (ts.performanceTime > 0 && P.audioLatencyMs.length < 100000) {
        const nowWall = performance.timeOrigin + performance.now();
        const playWall = performance.timeOrigin + ts.performanceTime + (at - ts.contextTime) * 1000;
        const total = playWall - wallMs, arrive = nowWall - wallMs, lead = (at - actx.currentTime) * 1000;
        P.audioLatencyMs.push(total);
        P.audioParts.push([arrive, lead, total - arrive - lead]);
      }
    }
  }

  // ---- messages -----------------------------------------------------------------------
  const logEl = $('log');
  P.said = [];
  function log(text) {
    if (P.said.length < 10000) P.said.push(text);
    const p = document.createElement('p'); p.textContent = text; logEl.appendChild(p);
    while (logEl.childNodes.length > 60) logEl.removeChild(logEl.firstChild);
    logEl.scrollTop = logEl.scrollHeight;
  }
  function say(text) { $('announce').textContent = text; log(text); }
  const WORDS = {
    'brick.grabbed': 'brick grabbed', 'brick.released': 'brick let go', 'brick.impact': 'impact',
    'brick.slot_filled': 'slot filled', 'brick.slot_emptied': 'slot emptied', 'button.down': 'button down',
    'button.up': 'button up', 'nano.snap': 'snap', 'nano.pull_off': 'pull-off', 'force.clamped': 'force at the limit',
    'switch.set': 'switch set', 'device.lost': 'hand lost', 'device.resumed': 'hand back',
  };
  // Every event is announced: those of half a second in one sentence, repeats counted, so a
  // screen reader is not flooded.
  const pending = new Map();
  let lastAnnounce = 0;
  function announceEvents(evs, now_) {
    for (const [, name] of evs) pending.set(name, (pending.get(name) || 0) + 1);
    const now = performance.now();
    if ((!now_ && now - lastAnnounce < 500) || pending.size === 0) return;
    lastAnnounce = now;
    const parts = [];
    for (const [name, c] of pending) parts.push((WORDS[name] || name.replace(/[._]/g, ' ')) + (c > 1 ? ` ×${c}` : ''));
    pending.clear();
    log(parts.join('; '));
  }
  let lastScore = null;
  function onFrame(f) {
    P.frames++;
    if (f.prims) P.lastFrame = f;
    for (const e of f.events || []) P.events.push(e);
    for (const s of f.sounds || []) P.sounds.push(s);
    announceEvents(f.events || []);
    const st = f.state;
    if (st) {
      const sc = st.score;
      if (sc !== undefined) {
        $('score').textContent = sc.toFixed(0);
        if (lastScore !== null && Math.round(sc) !== Math.round(lastScore)) say(`score ${sc.toFixed(0)}`);
        lastScore = sc;
      }
      const lab = (f.prims || []).find((p) => p.k === 'label');
      if (lab) $('task').textContent = lab.text;
    }
    $('time').textContent = f.time_s.toFixed(1) + ' s';
    if (f.device_force_n && P.hello) $('force').value = Math.min(1, Math.hypot(...f.device_force_n) / P.hello.max_force_n);
  }
  function onHello(h) {
    P.hello = h;
    $('title').textContent = h.scene;
    const ws_m = h.workspace_radius_m * h.mapping.workspace_scale * h.display_scale;
    cam.target = h.mapping.origin_m.map((x) => x * h.display_scale);
    cam.target[2] = Math.min(cam.target[2], ws_m * 0.15);
    cam.dist = ws_m * 1.35;
    const menu = $('menu'); menu.textContent = '';
    for (const s of h.switches) {
      const lab = document.createElement('label');
      const span = document.createElement('span'); span.textContent = s.name; span.title = s.doc; lab.appendChild(span);
      const inp = document.createElement('input');
      if (s.boolean) { inp.type = 'checkbox'; inp.checked = s.value == null ? true : s.value !== 0; }
      else {
        inp.type = 'number'; inp.min = s.min; inp.max = s.max; inp.step = 'any'; inp.placeholder = `${s.min}–${s.max}`;
        if (s.value != null) inp.value = String(s.value);
      }
      inp.setAttribute('aria-label', `${s.name}: ${s.doc}`); inp.id = 'sw-' + s.name;
      const b = document.createElement('button'); b.type = 'button'; b.textContent = 'set';
      b.setAttribute('aria-label', `set ${s.name}`);
      b.addEventListener('click', () => {
        const v = s.boolean ? (inp.checked ? 1 : 0) : Number(inp.value);
        if (!s.boolean && (inp.value === '' || !Number.isFinite(v))) { say(`${s.name}: enter a number from ${s.min} to ${s.max}`); return; }
        send({ type: 'switch', name: s.name, value: v });
      });
      lab.appendChild(inp); lab.appendChild(b); menu.appendChild(lab);
    }
    const nb = h.buttons.length;
    $('turnkeys').textContent = nb > 1 ? `keys 1–${Math.min(3, nb - 1)}: ${h.buttons.slice(1, 4).join(', ')} (held)` : 'no turn buttons on this device';
    $('start-msg').textContent = h.page_is_hand
      ? `${h.scene}. Press Start: the page is the hand (pointer, keyboard or gamepad).`
      : `${h.scene}. A device is the hand; this page shows and sounds the session.`;
    $('go').disabled = false; $('go').focus();
  }
  function onEnd(m) {
    announceEvents([], true);
    P.ended = m;
    const rows = [['how it ended', m.end], ['time', `${m.seconds.toFixed(2)} s`], ['score', (m.state.score ?? 0).toFixed(1)]];
    for (const k of ['slots_filled', 'house_score', 'dropped', 'comfort_exceeded_s', 'complete_s']) {
      if (m.state[k] === undefined) continue;
      const v = k === 'complete_s' && m.state[k] < 0 ? 'not complete' : String(+m.state[k].toFixed(3));
      rows.push([k.replace(/_/g, ' '), v]);
    }
    rows.push(['peak force', `${m.peak_device_force_n.toFixed(2)} N`]);
    rows.push(['events', String(m.events)]);
    rows.push(['missed 1 ms deadlines', String(m.missed_deadlines)]);
    if (m.input_latency_ms) rows.push(['input → force p99', `${m.input_latency_ms.p99.toFixed(1)} ms`]);
    if (m.recording_bytes) rows.push(['recording', `${m.recording_file} (${(m.recording_bytes / 1024).toFixed(0)} KiB)`]);
    const t = $('figs'); t.textContent = '';
    for (const [k, v] of rows) { const tr = t.insertRow(); tr.insertCell().textContent = k; tr.insertCell().textContent = v; }
    $('download').setAttribute('download', m.recording_file || 'recording.mcap');
    $('end').classList.remove('hidden'); $('start').classList.add('hidden');
    say(`session over: score ${(m.state.score ?? 0).toFixed(0)}`);
    $('download').focus();
  }
  let ws = null;
  function connect() {
    ws = new WebSocket(`ws://${location.host}/ws`);
    ws.binaryType = 'arraybuffer';
    ws.onmessage = (ev) => {
      if (typeof ev.data !== 'string') { onPcm(ev.data); return; }
      const m = JSON.parse(ev.data);
      if (m.type === 'frame') onFrame(m);
      else if (m.type === 'hello') onHello(m);
      else if (m.type === 'waiting') $('start-msg').textContent = `Waiting for ${m.for}…`;
      else if (m.type === 'role') { P.role = m.role; $('role').textContent = m.role === 'hand' ? 'the hand' : 'watching'; say(m.role === 'hand' ? 'you are the hand' : 'you are watching'); }
      else if (m.type === 'switched') { P.switched.push(m); say(`${m.name} set to ${m.value}`); }
      else if (m.type === 'error') { P.errors.push(m); say(m.message); }
      else if (m.type === 'end') onEnd(m);
    };
    ws.onclose = () => { if (!P.ended) say('the server closed the link'); };
  }
  $('go').addEventListener('click', () => {
    $('start').classList.add('hidden');
    startAudio();
    send({ type: 'start' });
    canvas.focus();
    setTimeout(() => sendHand(), 0);
  });

  // ---- the frame loop -----------------------------------------------------------------
  let lastT = performance.now();
  function loop(t) {
    const dt = Math.min(0.1, (t - lastT) / 1000); lastT = t;
    if (P.hello && P.role === 'hand') pollKeysAndPad(dt);
    if (!P.drawT0 && P.lastFrame) P.drawT0 = t;
    draw();
    requestAnimationFrame(loop);
  }
  resize();
  connect();
  requestAnimationFrame(loop);
})();
