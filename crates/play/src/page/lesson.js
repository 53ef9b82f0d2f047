// nanohaptics play: the lesson (`play --lesson`). The server's `lesson` message says where the
// student is; this module shows it: a question as a real form (a radio group, or a text area,
// each labelled) in the lesson card, the step's title and task in the side panel while the
// world runs, the completion with the pre- and post-test scores. What to do is said in the
// lesson's live region. Answers go to the server (`answer`), which keeps them; `?step=ID` in
// the page's address asks for that step alone (`step`), a demonstration.

import { $, P, say } from './page.js';
import { canvas } from './camera.js';
import { send } from './messages.js';

const QUESTION_PLACES = new Set(['pre_test', 'before', 'after', 'post_test']);
let askedStep = false;

// The question's form: a fieldset whose legend is the prompt, with a radio per choice, or a
// labelled text area; an Answer button submits it.
function questionForm(m) {
  const q = m.question;
  const form = $('lesson-form'); form.textContent = '';
  const fs = document.createElement('fieldset');
  const lg = document.createElement('legend'); lg.textContent = q.prompt; lg.id = 'lesson-prompt';
  fs.appendChild(lg);
  if (q.choices.length > 0) {
    q.choices.forEach((c, i) => {
      const lab = document.createElement('label');
      const r = document.createElement('input');
      r.type = 'radio'; r.name = 'choice'; r.value = String(i); r.id = `choice-${i}`;
      if (i === 0) r.required = true;
      lab.appendChild(r); lab.appendChild(document.createTextNode(' ' + c));
      fs.appendChild(lab);
    });
  } else {
    const lab = document.createElement('label'); lab.htmlFor = 'answer-text';
    lab.textContent = `Your answer (up to ${q.max_chars} characters)`;
    const ta = document.createElement('textarea');
    ta.id = 'answer-text'; ta.rows = 3; ta.maxLength = q.max_chars; ta.required = true;
    ta.setAttribute('aria-describedby', 'lesson-prompt');
    fs.appendChild(lab); fs.appendChild(ta);
  }
  form.appendChild(fs);
  const b = document.createElement('button'); b.type = 'submit'; b.id = 'answer-go'; b.textContent = 'Answer';
  form.appendChild(b);
  const first = form.querySelector('input, textarea');
  if (first) first.focus();
}

// Sends the form's answer: the checked choice's index, or the text.
function submitAnswer(e) {
  e.preventDefault();
  const m = P.lesson;
  if (!m || !m.question) return;
  if (m.question.choices.length > 0) {
    const r = $('lesson-form').querySelector('input[name=choice]:checked');
    if (!r) { say('choose one of the answers first'); return; }
    send({ type: 'answer', choice: Number(r.value) });
  } else {
    const t = $('answer-text').value;
    if (t.trim() === '') { say('write an answer first'); return; }
    send({ type: 'answer', text: t });
  }
  P.answersSent++;
}

// `lesson`: where the student is now.
export function onLesson(m) {
  P.lesson = m; P.lessons.push(m);
  if (!askedStep) {
    askedStep = true;
    const id = new URLSearchParams(location.search).get('step');
    if (id) send({ type: 'step', id });
  }
  $('lesson-title').textContent = m.title;
  $('lesson-step').textContent = m.step === null ? '' : `Step ${m.step + 1} of ${m.steps}: ${m.step_title}`;
  $('lesson-task').textContent = m.task;
  $('lesson-panel').classList.remove('hidden');
  $('lesson-now').textContent = m.step === null ? '' : `${m.step_title}: ${m.task}`;
  $('lesson-words').textContent = m.words;
  // A stopped world ended the lesson: its end screen stays. A completed one was a step's end
  // (seen as the session's by a page that connected after it): the lesson goes on.
  if (P.ended && P.ended.end !== 'completed') return;
  if (P.ended) { P.stepEnds.push(P.ended); P.ended = null; }
  const card = $('lesson');
  $('end').classList.add('hidden');
  if (QUESTION_PLACES.has(m.place)) {
    $('start').classList.add('hidden');
    card.classList.remove('hidden');
    $('lesson-h').textContent = m.place === 'pre_test' ? 'Before the lesson'
      : m.place === 'post_test' ? 'After the lesson'
      : m.place === 'before' ? 'Before you start' : 'What did you notice?';
    questionForm(m);
  } else if (m.place === 'finished') {
    card.classList.remove('hidden');
    $('lesson-h').textContent = 'The lesson is finished';
    const form = $('lesson-form'); form.textContent = '';
    if (m.score && m.score.pre[1] > 0) {
      const p = document.createElement('p'); p.id = 'lesson-score';
      p.textContent = `Before the lesson: ${m.score.pre[0]} of ${m.score.pre[1]} right. After: ${m.score.post[0]} of ${m.score.post[1]} right.`;
      form.appendChild(p);
    }
    $('lesson-h').setAttribute('tabindex', '-1'); $('lesson-h').focus();
  } else {
    // The step's world: Start once (the page becomes the hand), then each step at once.
    card.classList.add('hidden');
    if (P.role === 'hand') canvas.focus();
  }
}

// The lesson's `end` of a step's world: no end screen, the next `lesson` says what follows.
export function lessonRuns() { return P.lesson !== null; }

export function installLesson() {
  $('lesson-form').addEventListener('submit', submitAnswer);
}
