// The teacher page: every student's status from `class` messages, and the class's commands.
const q = location.search;
const proto = location.protocol === 'https:' ? 'wss:' : 'ws:';
const ws = new WebSocket(`${proto}//${location.host}/teacher/ws${q}`);
const $ = (id) => document.getElementById(id);
$('zip').href = `/recordings.zip${q}`;
let switches = [];
let lesson = null; // the class's lesson (title, steps with their locks), if it has one
const fmt = (x, d = 2) => (Number.isFinite(x) ? x.toFixed(d) : '–');
const field = (st, name) => {
  if (!st) return undefined;
  const f = st.state.find(([n]) => n === name);
  return f ? f[1] : undefined;
};

// Where a student is in the lesson, in a few words: `3 of 11 · Throw a brick · doing`.
function lessonPlace(l) {
  if (!l) return '–';
  if (l.step === null || l.step === undefined) return l.where;
  const place = { waiting: 'waiting for you', before: 'predicting', doing: 'doing the task', after: 'saying what they noticed' }[l.place] || l.place;
  return `${l.step + 1} of ${lesson.steps.length} · ${l.step_title} · ${place}`;
}

function row(s) {
  const st = s.status;
  const tr = document.createElement('tr');
  tr.dataset.student = s.name;
  const score = field(st, 'score');
  const filled = field(st, 'slots_filled') ?? field(st, 'filled');
  const slots = field(st, 'slots');
  const L = lesson ? 2 : 0; // the lesson's two columns after the state
  const cells = [
    s.name,
    st ? st.phase : '–',
    ...(lesson ? [lessonPlace(s.lesson), s.lesson && s.lesson.on_step_s != null ? `${fmt(s.lesson.on_step_s, 0)} s` : '–'] : []),
    s.pages > 0 ? `yes (${s.pages})` : 'no',
    st ? `${fmt(st.time_s, 1)} s` : '–',
    score === undefined ? '–' : fmt(score, 0),
    '',
    st ? `${fmt(st.force_n)} N` : '–',
    st ? String(st.missed) : '–',
    '',
  ];
  cells.forEach((c, i) => {
    const td = document.createElement('td');
    td.textContent = c;
    if (i === 1 && st) td.className = `phase-${st.phase}`;
    if (i >= 3 + L && i <= 7 + L) td.classList.add('num');
    if (L && i === 2) td.className = 'lesson-place';
    tr.appendChild(td);
  });
  const bp = tr.children[5 + L];
  bp.className = 'slots';
  if (filled !== undefined) {
    const n = slots !== undefined ? slots : filled;
    for (let k = 0; k < Math.max(n, filled); k++) {
      const b = document.createElement('span');
      if (k < filled) b.className = 'on';
      bp.appendChild(b);
    }
    bp.append(` ${filled}${slots !== undefined ? ` of ${slots}` : ''} filled`);
  } else bp.textContent = '–';
  const act = tr.children[8 + L];
  if (lesson) {
    // Each step whose world has closed: watch it again.
    for (const id of s.steps_run) {
      const a = document.createElement('a');
      const p = new URLSearchParams(q);
      p.set('s', s.token);
      p.set('step', id);
      a.href = `/replay?${p}`;
      a.target = '_blank';
      a.textContent = `Watch ${id}`;
      a.className = 'watch-step';
      a.setAttribute('aria-label', `watch ${s.name}'s step ${id} again`);
      act.append(a, ' ');
    }
  }
  if (st && st.phase !== 'ended') {
    const b = document.createElement('button');
    b.textContent = 'End';
    b.addEventListener('click', () => send({ type: 'end', student: s.name }));
    act.appendChild(b);
  } else if (st && !lesson) {
    // An ended session: watch it again (re-simulated from the recording) in a new tab.
    const a = document.createElement('a');
    const p = new URLSearchParams(q);
    p.set('s', s.token);
    a.href = `/replay?${p}`;
    a.target = '_blank';
    a.textContent = 'Watch';
    a.setAttribute('aria-label', `watch ${s.name}'s session again`);
    act.appendChild(a);
  }
  return tr;
}

function send(m) {
  if (ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(m));
}

// The lesson's steps (locked or open), its step chooser, and every answer as it comes.
function onLesson(c) {
  const first = !lesson;
  lesson = c.lesson;
  if (first) {
    for (const e of document.querySelectorAll('.lesson-col, #lesson-controls, #answers-box')) e.classList.remove('hidden');
    $('controls').querySelectorAll('label, #set').forEach((e) => e.classList.add('hidden'));
    $('lesson-step').replaceChildren(...lesson.steps.map((st, i) => {
      const o = document.createElement('option');
      o.value = st.id;
      o.textContent = `${i + 1}. ${st.title}`;
      return o;
    }));
  }
  $('lesson-title').textContent = `Lesson: ${lesson.title}`;
  $('lesson-steps').replaceChildren(...lesson.steps.map((st) => {
    const li = document.createElement('li');
    li.textContent = st.title;
    li.dataset.step = st.id;
    if (st.locked) li.className = 'locked';
    const on = c.students.filter((s) => s.lesson && s.lesson.step_id === st.id && !s.lesson.ended).map((s) => s.name);
    if (on.length) li.append(`: ${on.join(', ')}`);
    return li;
  }));
  const next = lesson.steps.find((st) => st.locked);
  $('open-next').disabled = !next;
  $('open-next').textContent = next ? `Open the next step (${next.title})` : 'Every step is open';
  const rows = [];
  for (const s of c.students) {
    for (const a of (s.lesson ? s.lesson.answers : [])) {
      const tr = document.createElement('tr');
      for (const t of [s.name, a.at, a.prompt, a.answer]) {
        const td = document.createElement('td');
        td.textContent = t;
        tr.appendChild(td);
      }
      rows.push(tr);
    }
  }
  $('answers').tBodies[0].replaceChildren(...rows);
}

function onClass(c) {
  $('scene').textContent = c.scene;
  if (c.lesson) onLesson(c);
  const playing = c.students.filter((s) => s.status && s.status.phase === 'playing').length;
  const code = c.join_code ? ` · join code ${c.join_code}` : '';
  const refused = Object.values(c.refused).reduce((a, b) => a + b, 0);
  $('summary').textContent =
    `${c.students.length} joined, ${playing} playing, ${c.ended} ended (at most ${c.max_students}) · ` +
    `${c.rate_hz} Hz${code} · ${refused} requests refused`;
  const body = $('students').tBodies[0];
  body.replaceChildren(...c.students.map(row));
  if (switches.length === 0 && c.switches.length > 0) {
    switches = c.switches;
    $('switch').replaceChildren(...switches.map((s) => {
      const o = document.createElement('option');
      o.value = s.name;
      o.textContent = `${s.name} (${s.boolean ? 'on/off' : `${s.min} to ${s.max}`})`;
      return o;
    }));
  }
  const who = $('who');
  const names = c.students.filter((s) => s.status && s.status.phase !== 'ended').map((s) => s.name);
  const have = [...who.options].slice(1).map((o) => o.value);
  if (names.join('\n') !== have.join('\n')) {
    const keep = who.value;
    who.replaceChildren(who.options[0], ...names.map((n) => {
      const o = document.createElement('option');
      o.value = n;
      o.textContent = n;
      return o;
    }));
    who.value = names.includes(keep) ? keep : '';
  }
}

ws.addEventListener('message', (ev) => {
  const m = JSON.parse(ev.data);
  if (m.type === 'class') onClass(m);
  else if (m.type === 'done') $('said').textContent = m.message;
  else if (m.type === 'error') $('said').textContent = `Refused: ${m.message}`;
});
ws.addEventListener('close', () => { $('summary').textContent = 'The class server has closed.'; });
$('set').addEventListener('click', () => {
  const m = { type: 'switch', name: $('switch').value, value: Number($('value').value) };
  if ($('who').value) m.student = $('who').value;
  send(m);
});
$('endall').addEventListener('click', () => send({ type: 'end_all' }));
$('open-next').addEventListener('click', () => send({ type: 'open_next' }));
$('open-step').addEventListener('click', () => send({ type: 'open_step', step: $('lesson-step').value }));
$('hold-step').addEventListener('click', () => send({ type: 'hold_step', step: $('lesson-step').value }));
