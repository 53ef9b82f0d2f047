// nanohaptics play: what the page says about the session's events. Every event name the
// worlds and the loop emit is classed here, in this one table (the test
// crates/play/tests/page_events.rs fails when a world or the loop emits a name it does not
// class, or when it classes a name nobody emits):
//   GAME   the game: written to the Events list and read out, as a short sentence;
//   NOW    the game, read out at once (assertive) as well as listed: the grip;
//   QUIET  the game, but heard or felt already (an impact's sound, a touch's force) or told
//          by another message (a switch: `switched`): not listed;
//   LOOP   the loop's timing, safety, device and diagnostic reports: never listed nor read
//          out; they stay in the recording and the end summary.
// A name the table does not know (a newer server) is not said: timing reports never reach
// the player by default.
// Numbers are counted from 1 for the player (brick 1 is the recording's brick 0).

const GAME = 'game', NOW = 'now', QUIET = 'quiet', LOOP = 'loop';

const one = (i) => (Number.isInteger(i) ? String(i + 1) : '?');
// A nano world member (`"tip"`, `{"atom": 2}`) or target (`{"substrate_atom": 812}`,
// `"substrate_plane"`, `{"atom": 5}`) in words.
function member(m) {
  if (m === 'tip') return 'tip';
  if (m && m.atom !== undefined) return `atom ${one(m.atom)}`;
  return 'tip';
}
function target(t) {
  if (t === 'substrate_plane' || (t && t.substrate_atom !== undefined)) return 'the surface';
  if (t && t.atom !== undefined) return `atom ${one(t.atom)}`;
  return 'the surface';
}
function grip(down) {
  // The grip is button 0 (the page's grip: pointer button, Space, right trigger).
  return (d, hello) => (hello && hello.buttons.length && d === hello.buttons[0] ? (down ? 'grip on' : 'grip off') : null);
}

// name → [class, sentence(detail, hello)] (detail: the parsed JSON detail, or the detail
// text when it is not JSON; the sentence may be null: nothing to say).
export const EVENTS = new Map([
  // The brick world.
  ['brick.spawned', [GAME, (d) => `new brick ${one(d.brick)} in the loading zone`]],
  ['brick.grabbed', [GAME, (d) => `grabbed brick ${one(d.brick)}`]],
  ['brick.grab_missed', [GAME, () => 'grab missed: no brick in reach']],
  ['brick.released', [GAME, (d) => `let go of brick ${one(d.brick)}`]],
  ['brick.thrown', [GAME, (d) => `threw brick ${one(d.brick)}`]],
  ['brick.rotated', [GAME, (d) => `turned brick ${one(d.brick)} about ${d.axis}`]],
  ['brick.rotation_blocked', [GAME, (d) => `brick ${one(d.brick)} cannot turn about ${d.axis}: blocked`]],
  ['brick.slot_filled', [GAME, (d) => `slot ${one(d.slot)} filled with brick ${one(d.brick)}`]],
  ['brick.slot_vacated', [GAME, (d) => `slot ${one(d.slot)} emptied: brick ${one(d.brick)} left it`]],
  ['brick.impact', [QUIET, null]],
  ['brick.touch_began', [QUIET, null]],
  ['brick.touch_ended', [QUIET, null]],
  ['brick.input_rejected', [LOOP, null]],
  // The nano world.
  ['nano.atom_spawned', [GAME, (d) => `new atom ${one(d.atom)} in the loading zone`]],
  ['nano.snap', [GAME, (d) => `snap: ${member(d.member)} to ${target(d.target)}`]],
  ['nano.pull_off', [GAME, (d) => `pull-off: ${member(d.member)} from ${target(d.target)}`]],
  ['nano.atom_attached', [GAME, (d) => `atom ${one(d.atom)} jumped onto the tip`]],
  ['nano.atom_picked_up', [GAME, (d) => `picked up atom ${one(d.atom)}`]],
  ['nano.atom_transferred', [GAME, (d) => `atom ${one(d.atom)} left the tip onto ${target(d.onto)}`]],
  ['nano.atoms_thrown_off', [GAME, (d) => (d.atoms === 1 ? '1 atom shaken off the tip' : `${d.atoms} atoms shaken off the tip`)]],
  ['nano.slot_filled', [GAME, (d) => `slot ${one(d.slot)} filled`]],
  ['nano.slot_emptied', [GAME, (d) => `slot ${one(d.slot)} emptied`]],
  ['nano.house_complete', [GAME, () => 'house complete']],
  ['nano.saturated', [LOOP, null]],
  ['nano.error', [LOOP, null]],
  ['nano.step_error', [LOOP, null]],
  // The wall.
  ['wall.contact_begin', [GAME, () => 'touching the wall']],
  ['wall.contact_end', [GAME, () => 'off the wall']],
  ['wall.stiffness_capped', [LOOP, null]],
  // The optical tweezers.
  ['ot.grab', [GAME, () => 'grabbed the particle']],
  ['ot.grab_missed', [GAME, () => 'grab missed: the particle is out of reach']],
  ['ot.release', [GAME, () => 'let go of the particle']],
  ['ot.clipped', [LOOP, null]],
  ['ot.tick_map', [LOOP, null]],
  ['ot.envelope_grid', [LOOP, null]],
  ['ot.controller_error', [LOOP, null]],
  ['ot.physics_error', [LOOP, null]],
  // The loop: the grip, the menu, and its own reports.
  ['button.down', [NOW, grip(true)]],
  ['button.up', [NOW, grip(false)]],
  ['switch.set', [QUIET, null]],
  ['deadline.missed', [LOOP, null]],
  ['safety.config', [LOOP, null]],
  ['safety.passivity', [LOOP, null]],
  ['safety.rate_limited', [LOOP, null]],
  ['force.clamped', [LOOP, null]],
  ['force.invalid', [LOOP, null]],
  ['scene.stiffness_over_cap', [LOOP, null]],
  ['input.invalid', [LOOP, null]],
  ['input.valid', [LOOP, null]],
  ['device.fit', [LOOP, null]],
  ['device.sample_late', [LOOP, null]],
  ['device.lost', [LOOP, null]],
  ['device.resumed', [LOOP, null]],
]);

// The class of an event name: 'game', 'now', 'quiet' or 'loop' ('loop' for a name the table
// does not know).
export function eventClass(name) {
  const e = EVENTS.get(name);
  return e ? e[0] : LOOP;
}

// What the page says about event `name` with detail `detail` (the recording's text), for the
// hello `hello`: a short sentence, or null (nothing to say: not a game event, or one the
// player hears or feels).
export function sentence(name, detail, hello) {
  const e = EVENTS.get(name);
  if (!e || !e[1] || (e[0] !== GAME && e[0] !== NOW)) return null;
  let d = detail;
  try { d = JSON.parse(detail); } catch (err) { d = detail; }
  if (d === null || d === undefined) d = {};
  try { return e[1](d, hello) || null; } catch (err) { return null; }
}
