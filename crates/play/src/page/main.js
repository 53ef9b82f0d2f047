// nanohaptics play: the page. Draws the frames the server sends, sends the hand, synthesises
// the sound from the server's sound ticks. Plain JavaScript modules, no library, built into the server:
//   page.js      what the modules share (window.__play, the spoken log)
//   camera.js    the orbit camera and the projection
//   draw.js      a frame's shapes on the canvas
//   input.js     pointer, keyboard and gamepad as the hand
//   sound.js     the audio output, the synthesis's node and the sound's counts
//   synth.js     the synthesis, an AudioWorklet processor (render --audio's, ported)
//   messages.js  the link's worker and a handler per message type
//   link.js      the link, a dedicated Worker: the WebSocket; the sound ticks go from it
//                straight to the synthesis's port, the text messages to this thread
//   route.js     the link's routing: the ticks counted and to the synthesis, a lesson's
//                restarts and the ends in their order (no socket, no clock: tested alone)
//   events.js    the events in words: which the player hears, which stay in the recording
//   lesson.js    the lesson (play --lesson): its questions as forms, the step's task, the end
// window.__play holds figures for tests and benches.

import { $, P } from './page.js';
import { canvas, resize } from './camera.js';
import { draw } from './draw.js';
import { gripping, installInput, pollKeysAndPad, sendHand } from './input.js';
import { startAudio } from './sound.js';
import { connect, send } from './messages.js';
import { installLesson } from './lesson.js';

$('go').addEventListener('click', () => {
  $('start').classList.add('hidden');
  startAudio();
  send({ type: 'start' });
  canvas.focus();
  setTimeout(() => sendHand(), 0);
});

// The frame loop: the keys and gamepad (while the hand), then the drawing.
let lastT = performance.now();
function loop(t) {
  const dt = Math.min(0.1, (t - lastT) / 1000); lastT = t;
  if (P.hello && P.role === 'hand') pollKeysAndPad(dt);
  if (!P.drawT0 && P.lastFrame) P.drawT0 = t;
  draw(P.lastFrame, P.hello, gripping());
  requestAnimationFrame(loop);
}

window.addEventListener('resize', resize);
resize();
installInput();
installLesson();
connect();
requestAnimationFrame(loop);
