// canmotion-web page: plain JS, no framework. Receives JSON from /ws.
'use strict';
let ws = null, nextId = 1, commandsAllowed = false;
const prev = {};   // axis name -> previous fields, for derived events
const peaks = {};  // axis name -> {min, max} of pos_err
const events = [];

function el(id) { return document.getElementById(id); }

function addEvent(text) {
  const t = new Date().toISOString();
  events.push([t, text]);
  renderEvents();
}

function renderEvents() {
  const f = el('filter').value.toLowerCase();
  const body = el('events').tBodies[0];
  body.textContent = '';
  for (const [t, text] of events) {
    if (f && !text.toLowerCase().includes(f)) continue;
    const tr = body.insertRow();
    tr.insertCell().textContent = t;
    tr.insertCell().textContent = text;
  }
}

function csv() {
  const q = s => '"' + String(s).replace(/"/g, '""') + '"';
  const text = 'time,event\n' + events.map(e => e.map(q).join(',')).join('\n') + '\n';
  const a = document.createElement('a');
  a.href = URL.createObjectURL(new Blob([text], {type: 'text/csv'}));
  a.download = 'canmotion-events.csv';
  a.click();
}

function send(obj) {
  if (!ws || ws.readyState !== WebSocket.OPEN) { addEvent('not connected: ' + obj.verb); return; }
  obj.type = 'command';
  obj.id = String(nextId++);
  ws.send(JSON.stringify(obj));
}

function command(verb, axis, extra) {
  const what = verb === 'MODE' ? 'MODE ' + extra.mode : verb + ' on ' + axis;
  if (!confirm('Send ' + what + '?')) return;
  send(Object.assign({verb: verb, axis: axis}, extra || {}));
}

function axisCard(a) {
  let card = document.getElementById('axis-' + a.axis);
  if (card) return card;
  card = document.createElement('div');
  card.className = 'axis';
  card.id = 'axis-' + a.axis;
  card.innerHTML = '<h3></h3><table></table><div class="buttons"></div>';
  card.querySelector('h3').textContent = a.axis;
  const buttons = card.querySelector('.buttons');
  for (const v of ['MSO', 'MSF', 'MAFR', 'MAS', 'MAH', 'MASR']) {
    const b = document.createElement('button');
    b.textContent = v;
    b.onclick = () => command(v, a.axis);
    buttons.appendChild(b);
  }
  const reset = document.createElement('button');
  reset.textContent = 'reset peak';
  reset.onclick = () => { delete peaks[a.axis]; };
  buttons.appendChild(reset);
  el('axes').appendChild(card);
  return card;
}

const shown = ['state', 'drive', 'phase', 'cmd_pos', 'act_pos', 'cmd_vel', 'act_vel', 'pos_err',
               'faults', 'status_bits', 'motion_bits', 'last_emcy', 'failure'];

function showAxis(a) {
  const card = axisCard(a);
  const e = parseFloat(a.pos_err);
  if (!isNaN(e)) {
    const p = peaks[a.axis] || (peaks[a.axis] = {min: e, max: e});
    p.min = Math.min(p.min, e); p.max = Math.max(p.max, e);
  }
  const rows = shown.filter(k => k in a).map(k => [k, a[k]]);
  if (peaks[a.axis]) rows.push(['pos_err peak', peaks[a.axis].min + ' .. ' + peaks[a.axis].max]);
  const table = card.querySelector('table');
  table.textContent = '';
  for (const [k, v] of rows) {
    const tr = table.insertRow();
    tr.insertCell().textContent = k;
    const td = tr.insertCell();
    td.textContent = v;
    td.className = 'v-' + k.replace(/ /g, '_');
  }
  card.classList.toggle('faulted', a.faults && a.faults !== '-');
  const p = prev[a.axis];
  if (p) {
    for (const k of ['state', 'drive', 'faults', 'last_emcy', 'failure'])
      if (p[k] !== a[k]) addEvent(a.axis + ' ' + k + ': ' + (p[k] || '-') + ' -> ' + (a[k] || '-'));
  } else {
    addEvent(a.axis + ' seen: state ' + a.state);
  }
  prev[a.axis] = a;
}

function showStatus(m) {
  el('daemon').classList.add('hidden');
  commandsAllowed = m.commands;
  el('cmdstate').textContent = m.commands ? 'commands allowed' : 'commands disabled';
  const s = m.stats;
  el('period').textContent = s.period_ms || '?';
  const us = k => s[k] === undefined ? '-' : (parseFloat(s[k]) / 1000).toFixed(1);
  el('latency').textContent = us('latency_p50_ns') + ' / ' + us('latency_p99_ns') + ' / ' + us('latency_max_ns');
  el('overruns').textContent = s.overruns || '0';
  el('missed').textContent = s.missed_deadlines || '0';
  const faulted = m.axes.filter(a => a.faults && a.faults !== '-');
  el('fault').classList.toggle('hidden', faulted.length === 0);
  el('fault').textContent = faulted.map(a => 'FAULT ' + a.axis + ': ' + a.faults).join('; ');
  for (const a of m.axes) showAxis(a);
}

function onMessage(ev) {
  const m = JSON.parse(ev.data);
  if (m.type === 'status') showStatus(m);
  else if (m.type === 'daemon') {
    el('daemon').classList.remove('hidden');
    el('daemon').textContent = 'daemon not reachable: ' + m.error;
  } else if (m.type === 'answer') {
    addEvent((m.ok ? 'OK ' : 'ERR ') + m.text);
  }
}

function connect() {
  ws = new WebSocket((location.protocol === 'https:' ? 'wss://' : 'ws://') + location.host + '/ws');
  ws.onmessage = onMessage;
  ws.onclose = () => {
    el('daemon').classList.remove('hidden');
    el('daemon').textContent = 'canmotion-web not reachable (reconnecting)';
    setTimeout(connect, 1000);
  };
}

el('filter').oninput = renderEvents;
el('csv').onclick = csv;
for (const b of document.querySelectorAll('[data-mode]'))
  b.onclick = () => command('MODE', '', {mode: b.dataset.mode});
connect();
