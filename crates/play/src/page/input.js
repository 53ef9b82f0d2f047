// nanohaptics play: the hand. The page's pointer, keyboard and gamepad move a point of the
// unit ball (right, away, up in the device frame) and press the device's buttons; while the
// page is the hand it sends that point as `input` messages. Keys and the right mouse button
// also orbit, tilt and zoom the camera.

import { P } from './page.js';
import { canvas, cam, horiz } from './camera.js';
import { send } from './messages.js';
import { toggleMute } from './sound.js';

// The hand: `n` the point of the unit ball, the grips, the turn buttons, the last input sent.
export const hand = { n: [0, 0, 0], grip: false, pointerGrip: false, turn: [false, false, false], dirty: true, seq: 0, lastSent: 0 };
P.hand = hand;
const held = new Map(); // key → speed factor (Shift: fine moves)
let gpGrip = false, gpTurn = [false, false, false], lastRumble = 0, rumbling = false;

// Whether the hand grips (the pointer's button, Space, or the gamepad's right trigger).
export function gripping() { return hand.grip || hand.pointerGrip || gpGrip; }

function clampBall() {
  const r = Math.hypot(...hand.n);
  if (r > 1) hand.n = hand.n.map((x) => x / r * (1 - 1e-12));
  hand.n = hand.n.map((x) => Math.max(-1, Math.min(1, x)));
}

// The button bits: bit 0 the grip, bits 1–3 the turn buttons the device has.
function buttons() {
  let b = gripping() ? 1 : 0;
  const nb = P.hello ? P.hello.buttons.length : 1;
  for (let i = 0; i < 3; i++) if ((hand.turn[i] || gpTurn[i]) && i + 1 < nb) b |= 1 << (i + 1);
  return b;
}

// Sends the hand as an `input` message, only while this page is the hand; `tStamp`: when the
// event happened on the page's clock (performance.now() ms; now if not given).
export function sendHand(tStamp) {
  if (!P.hello || !P.hello.page_is_hand || P.role !== 'hand' || P.ended) return;
  clampBall();
  hand.seq++;
  send({ type: 'input', seq: hand.seq, pos: hand.n, buttons: buttons(), t_ms: performance.timeOrigin + (tStamp || performance.now()) });
  P.inputsSent++;
  hand.dirty = false; hand.lastSent = performance.now();
}

// The pointer over the canvas: the hand's horizontal position (its height stays).
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

const MOVE = { ArrowLeft: [-1, 0, 0], ArrowRight: [1, 0, 0], ArrowUp: [0, 1, 0], ArrowDown: [0, -1, 0], PageUp: [0, 0, 1], PageDown: [0, 0, -1] };
const KEY_SPEED = 0.5; // unit-ball radii per second
// While keys move the hand it is stepped and sent every KEY_STEP_MS, not only at the frame
// rate: a hand sent at 60 Hz moves in 16 ms steps (6.7 mm in the brick world at full key
// speed), and the brick world's release estimate reads the hand between two steps as at
// rest, so Space never threw a brick. In 4 ms steps (1.6 mm) about half the releases read as
// throws (BENCHMARKS.md, "the built-in module by keyboard alone"); a late timer still gives 0.
const KEY_STEP_MS = 4;
let lastKeyStep = performance.now();

// Moves the hand by the keys held since the last key step; whether it moved.
function stepKeys() {
  const t = performance.now();
  const dt = Math.min(0.1, (t - lastKeyStep) / 1000); lastKeyStep = t;
  for (const [k, f] of held) {
    const m = MOVE[k], v = KEY_SPEED * f * dt;
    if (m[2]) { hand.n[2] += m[2] * v; }
    else { const [x, y] = horiz(m[0], m[1]); hand.n[0] += x * v; hand.n[1] += y * v; }
  }
  return held.size > 0;
}

// Listens to the pointer, the wheel and the keys.
export function installInput() {
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
  window.addEventListener('keydown', (e) => {
    if (e.target && ['INPUT', 'TEXTAREA', 'BUTTON', 'A'].includes(e.target.tagName)) return;
    const k = e.key;
    if (MOVE[k]) { if (!held.size) stepKeys(); held.set(k, e.shiftKey ? 0.2 : 1); e.preventDefault(); }
    else if (k === ' ') { if (!e.repeat) { stepKeys(); hand.grip = !hand.grip; sendHand(e.timeStamp); } e.preventDefault(); }
    else if (k === '1' || k === '2' || k === '3') { hand.turn[+k - 1] = true; sendHand(e.timeStamp); }
    else if (k === 'a' || k === 'A') cam.yaw += 0.08;
    else if (k === 'd' || k === 'D') cam.yaw -= 0.08;
    else if (k === 'w' || k === 'W') cam.pitch = Math.min(1.5, cam.pitch + 0.05);
    else if (k === 's' || k === 'S') cam.pitch = Math.max(-0.1, cam.pitch - 0.05);
    else if (k === '+' || k === '=') cam.dist *= 0.9;
    else if (k === '-') cam.dist /= 0.9;
    else if (k === 'm' || k === 'M') toggleMute();
    else if (k === 'e' || k === 'E') { if (!e.repeat) send({ type: 'end' }); }
  });
  window.addEventListener('keyup', (e) => {
    held.delete(e.key);
    if (e.key === '1' || e.key === '2' || e.key === '3') { hand.turn[+e.key - 1] = false; sendHand(e.timeStamp); }
  });
  setInterval(() => { if (held.size && P.hello && P.role === 'hand' && stepKeys()) sendHand(); }, KEY_STEP_MS);
}

// Moves the hand by the keys held and the gamepad over `dt` s, rumbles the gamepad with the
// force, and sends the hand when it moved (and at least every 100 ms).
export function pollKeysAndPad(dt) {
  let moved = stepKeys();
  const pads = navigator.getGamepads ? navigator.getGamepads() : [];
  for (const gp of pads) {
    if (!gp) continue;
    const dz = (v) => (Math.abs(v) < 0.12 ? 0 : v);
    const [x, y] = horiz(dz(gp.axes[0] || 0), -dz(gp.axes[1] || 0));
    const h = -dz(gp.axes[3] || 0);
    if (x || y || h) { hand.n[0] += x * KEY_SPEED * dt; hand.n[1] += y * KEY_SPEED * dt; hand.n[2] += h * KEY_SPEED * dt; moved = true; }
    const grip = !!(gp.buttons[7] && gp.buttons[7].value > 0.5);
    const turns = [4, 5, 3].map((i) => !!(gp.buttons[i] && gp.buttons[i].pressed));
    if (grip !== gpGrip || turns.some((t, i) => t !== gpTurn[i])) { gpGrip = grip; gpTurn = turns; moved = true; }
    // The rumble follows the force of the last frame (its share of the device's largest),
    // renewed every 60 ms or more; a force under 2 % stops it (one request of magnitude 0).
    const f = P.lastFrame && P.lastFrame.device_force_n;
    if (gp.vibrationActuator && f && performance.now() - lastRumble > 60) {
      const m = Math.min(1, Math.hypot(...f) / P.hello.max_force_n);
      const strong = m > 0.02 ? m : 0;
      if (strong > 0 || rumbling) {
        lastRumble = performance.now(); rumbling = strong > 0;
        gp.vibrationActuator.playEffect('dual-rumble', { duration: 80, strongMagnitude: strong, weakMagnitude: strong * 0.5 }).catch(() => {});
      }
    }
    break;
  }
  if (moved || performance.now() - hand.lastSent > 100) sendHand();
}
