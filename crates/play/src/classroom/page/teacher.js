// The teacher page: every student's status from `class` messages, and the class's commands.
const q = location.search;
const proto = location.protocol === 'https:' ? 'wss:' : 'ws:';
const ws = new WebSocket(`${proto}//${location.host}/teacher/ws${q}`);
const $ = (id) => document.getElementById(id);
$('zip').href = `/recordings.zip${q}`;
let switches = [];
const fmt = (x, d = 2) => (Number.isFinite(x) ? x.toFixed(d) : '–');
const field = (st, name) => {
  if (!st) return undefined;
  const f = st.state.find(([n]) => n === name);
  return f ? f[1] : undefined;
};

function row(s) {
  const st = s.status;
  const tr = document.createElement('tr');
  tr.dataset.student = s.name;
  const score = field(st, 'score');
  const filled = field(st, 'slots_filled') ?? field(st, 'filled');
  const slots = field(st, 'slots');
  const cells = [
    s.name,
    st ? st.phase : '–',
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
    if (i >= 3 && i <= 7) td.classList.add('num');
    tr.appendChild(td);
  });
  const bp = tr.children[5];
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
  if (st && st.phase !== 'ended') {
    const b = document.createElement('button');
    b.textContent = 'End';
    b.addEventListener('click', () => send({ type: 'end', student: s.name }));
    tr.children[8].appendChild(b);
  } else if (st) {
    // An ended session: watch it again (re-simulated from the recording) in a new tab.
    const a = document.createElement('a');
    const p = new URLSearchParams(q);
    p.set('s', s.token);
    a.href = `/replay?${p}`;
    a.target = '_blank';
    a.textContent = 'Watch';
    a.setAttribute('aria-label', `watch ${s.name}'s session again`);
    tr.children[8].appendChild(a);
  }
  return tr;
}

function send(m) {
  if (ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(m));
}

function onClass(c) {
  $('scene').textContent = c.scene;
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
