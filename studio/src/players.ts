// Players: the tactical board played back from TRACKS.csv (field positions x_m, y_m per frame):
// a top view with ids, 2 s trails and the zones of a zones file, play/pause, a time slider and
// each player's speed over time (uPlot).
import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import * as api from './api';
import { el, fileSelect, optionsSelect, labelled, status, FieldMap } from './ui';
import { drawZones, Zone } from './zones';

interface Tracks {
  rows: (number | null)[][]; // frame, id, bb_left, bb_top, bb_width, bb_height, x_m, y_m, time_s
}

export async function playersPage(root: HTMLElement): Promise<void> {
  const [list, info] = await Promise.all([api.files(), api.info()]);
  const tracks = fileSelect('pl-tracks', list, ['csv']);
  const guess = list.find((f) => f.kind === 'csv' && /track|players/i.test(f.path) && !/_2d/.test(f.path));
  if (guess) tracks.value = guess.path;
  const field = optionsSelect('pl-field', info.fields, 'robocup-msl');
  const zonesFile = fileSelect('pl-zones', list, ['json'], true);
  const chart = el('div', { id: 'pl-chart' });
  const load = el('button', { id: 'pl-load', text: 'Show' });
  const play = el('button', { id: 'pl-play', text: '▶ Play' });
  const time = el('input', { id: 'pl-time', type: 'range', min: '0', max: '0', value: '0' });
  const timeLabel = el('span', { id: 'pl-time-label' });
  const board = el('canvas', { id: 'pl-board', width: '900', height: '600' });
  const msg = el('div', { id: 'pl-status', class: 'status' });
  root.replaceChildren(
    el('section', { class: 'controls' }, labelled('Tracks', tracks), labelled('Field', field), labelled('Zones', zonesFile), load, play),
    el('div', { class: 'main-view' }, board, el('div', {}, labelled('Time', el('span', {}, time, timeLabel))), chart, msg),
  );

  let fmap: FieldMap | null = null;
  let frames: number[] = [];
  let byFrame = new Map<number, { id: number; x: number; y: number }[]>();
  let times = new Map<number, number>();
  let timer = 0;
  let zones: Zone[] = [];
  let plot: uPlot | null = null;

  const colourOf = (id: number) => `hsl(${(id * 67) % 360}, 80%, 60%)`;

  function draw(i: number) {
    if (!fmap) return;
    const ctx = fmap.draw();
    drawZones(ctx, fmap, zones);
    const f = frames[i];
    const t = times.get(f) ?? 0;
    // Trails: the last 2 s.
    for (let j = Math.max(0, i - 1); j >= 0 && t - (times.get(frames[j]) ?? 0) <= 2; --j) {
      for (const p of byFrame.get(frames[j]) ?? []) {
        const [x, y] = fmap.toCanvas(p.x, p.y);
        ctx.fillStyle = colourOf(p.id);
        ctx.globalAlpha = 0.35;
        ctx.fillRect(x - 1.5, y - 1.5, 3, 3);
      }
    }
    ctx.globalAlpha = 1;
    ctx.font = 'bold 12px sans-serif';
    const now = byFrame.get(f) ?? [];
    for (const p of now) {
      const [x, y] = fmap.toCanvas(p.x, p.y);
      ctx.fillStyle = colourOf(p.id);
      ctx.beginPath();
      ctx.arc(x, y, 8, 0, 2 * Math.PI);
      ctx.fill();
      ctx.fillStyle = '#000';
      ctx.fillText(String(p.id), x - 4, y + 4);
    }
    timeLabel.textContent = ` t = ${t.toFixed(2)} s, frame ${f}, ${now.length} players`;
    board.dataset.frame = String(f);
    plot?.setCursor({ left: plot.valToPos(t, 'x'), top: 10 });
  }

  // Speed of each player (m/s) between frames, averaged over 5 steps; the 12 longest tracks.
  function speedChart() {
    plot?.destroy();
    plot = null;
    const t = frames.map((f) => times.get(f) ?? 0);
    const byId = new Map<number, Map<number, { x: number; y: number }>>();
    frames.forEach((f, i) => {
      for (const p of byFrame.get(f) ?? []) {
        if (!byId.has(p.id)) byId.set(p.id, new Map());
        byId.get(p.id)!.set(i, p);
      }
    });
    const ids = [...byId.keys()].sort((a, b) => byId.get(b)!.size - byId.get(a)!.size).slice(0, 12).sort((a, b) => a - b);
    const series: (number | null)[][] = ids.map((id) => {
      const track = byId.get(id)!;
      const raw = t.map((_, i) => {
        const a = track.get(i - 1);
        const b = track.get(i);
        return a && b && t[i] > t[i - 1] ? Math.hypot(b.x - a.x, b.y - a.y) / (t[i] - t[i - 1]) : null;
      });
      return raw.map((_, i) => {
        const w = raw.slice(Math.max(0, i - 2), i + 3).filter((v): v is number => v !== null);
        return raw[i] === null || !w.length ? null : w.reduce((a, b) => a + b, 0) / w.length;
      });
    });
    if (!t.length) return;
    plot = new uPlot({
      width: board.clientWidth || 900, height: 190,
      series: [{ label: 't (s)' }, ...ids.map((id) => ({ label: `id ${id}`, stroke: colourOf(id), width: 1.2, points: { show: false } }))],
      axes: [{ label: 'time (s)', stroke: '#ccc' }, { label: 'speed (m/s)', stroke: '#ccc' }],
      scales: { x: { time: false } },
    }, [t, ...series] as uPlot.AlignedData, chart);
  }

  load.onclick = async () => {
    try {
      const [f, tr] = await Promise.all([api.get<api.FieldModel>('/api/field', { name: field.value }), api.get<Tracks>('/api/tracks', { path: tracks.value })]);
      fmap = new FieldMap(board, f);
      byFrame = new Map();
      times = new Map();
      for (const r of tr.rows) {
        const [frame, id, , , , , x, y, t] = r as number[];
        if (x === null || y === null) continue;
        if (!byFrame.has(frame)) byFrame.set(frame, []);
        byFrame.get(frame)!.push({ id, x, y });
        times.set(frame, t ?? frame / 25);
      }
      frames = [...byFrame.keys()].sort((a, b) => a - b);
      zones = zonesFile.value ? await api.get<Zone[]>('/api/zones', { path: zonesFile.value }) : [];
      speedChart();
      time.max = String(Math.max(0, frames.length - 1));
      time.value = '0';
      draw(0);
      status(msg, frames.length ? `${tr.rows.length} rows, ${frames.length} frames with field positions` : 'no field positions (x_m, y_m) in this file: track with a calibrated camera', !frames.length);
    } catch (e) {
      status(msg, (e as Error).message, true);
    }
  };
  time.addEventListener('input', () => draw(Number(time.value)));
  play.onclick = () => {
    if (timer) {
      clearInterval(timer);
      timer = 0;
      play.textContent = '▶ Play';
      return;
    }
    play.textContent = '❚❚ Pause';
    timer = window.setInterval(() => {
      const i = (Number(time.value) + 1) % Math.max(1, frames.length);
      time.value = String(i);
      draw(i);
    }, 40);
  };
}
