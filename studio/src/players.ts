// Players: the tactical board played back from TRACKS.csv (field positions x_m, y_m per frame):
// a top view with ids, teams (a `team` column, when the file has one), 2 s trails and the zones
// of a zones file; beside it the video the tracks came from (TRACKS frame N is video frame N-1,
// MOTChallenge numbering) with each player's box; play/pause and a time slider drive both.
// Below: the zone alerts on a timeline (who was in which zone when), each player's speed over
// time (uPlot), a heat map of the time spent per 1 m cell (one player or all) with its colour
// scale in seconds, and a table of distance, top and mean speed, sprints and zone time, as
// `fieldvision stats` computes them (/api/players/stats). Export writes what the page shows into
// a folder of the working folder (/api/players/export): the stats report's tables and images and
// the page's own heat map (with its scale), board, speed chart and alert timeline as PNG.
import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import * as api from './api';
import { el, fileSelect, optionsSelect, labelled, status, FieldMap, rampColour } from './ui';
import { drawZones, Zone } from './zones';

interface Tracks {
  rows: (number | null)[][]; // frame, id, bb_left, bb_top, bb_width, bb_height, x_m, y_m, time_s, team
}

interface Player {
  id: number;
  x: number;
  y: number;
  box: number[] | null; // left, top, width, height (px)
  team: number | null;
}

interface PlayerStats {
  players: { id: number; team: number; distance_m: number; top_speed_mps: number; mean_speed_mps: number; sprints: number; zone_time_s: Record<string, number> }[];
  events: { zone: string; id: number; enter_s: number; exit_s: number }[];
  summary: string;
}

const teamColours = ['#f44', '#48f', '#fd3', '#3d6'];

export async function playersPage(root: HTMLElement): Promise<void> {
  const [list, info] = await Promise.all([api.files(), api.info()]);
  const tracks = fileSelect('pl-tracks', list, ['csv']);
  const guess = list.find((f) => f.kind === 'csv' && /track|players/i.test(f.path) && !/_2d/.test(f.path));
  if (guess) tracks.value = guess.path;
  const field = optionsSelect('pl-field', info.fields, 'robocup-msl');
  const zonesFile = fileSelect('pl-zones', list, ['json'], true);
  const video = fileSelect('pl-video-file', list, ['video', 'images'], true);
  const chart = el('div', { id: 'pl-chart' });
  const load = el('button', { id: 'pl-load', text: 'Show' });
  const play = el('button', { id: 'pl-play', text: '▶ Play' });
  const time = el('input', { id: 'pl-time', type: 'range', min: '0', max: '0', value: '0' });
  const timeLabel = el('span', { id: 'pl-time-label' });
  const board = el('canvas', { id: 'pl-board', width: '900', height: '600' });
  const videoCanvas = el('canvas', { id: 'pl-video', width: '640', height: '480' });
  const heatWho = el('select', { id: 'pl-heat-id' });
  const heat = el('canvas', { id: 'pl-heat', width: '900', height: '600' });
  const legend = el('canvas', { id: 'pl-heat-legend', width: '900', height: '46' });
  const table = el('table', { id: 'pl-table' });
  const alerts = el('canvas', { id: 'pl-alerts', width: '1400', height: '60' });
  const msg = el('div', { id: 'pl-status', class: 'status' });
  const exportOut = el('input', { id: 'pl-export-out', value: 'players_export', size: '22', title: 'a folder of the working folder (made when absent)' });
  const exportReplace = el('input', { id: 'pl-export-replace', type: 'checkbox' }) as HTMLInputElement;
  const exportButton = el('button', { id: 'pl-export', text: 'Export' });
  const exportMsg = el('div', { id: 'pl-export-status', class: 'status' });
  root.replaceChildren(
    el('section', { class: 'controls' }, labelled('Tracks', tracks), labelled('Field', field), labelled('Zones', zonesFile),
      labelled('Video (side by side)', video), load, play),
    el('div', { class: 'side-by-side' },
      el('div', { class: 'half' }, board),
      el('div', { class: 'half' }, videoCanvas)),
    el('div', {}, labelled('Time', el('span', {}, time, timeLabel))), msg,
    el('h3', { text: 'Zone alerts' }), alerts,
    el('h3', { text: 'Speed (m/s)' }), chart,
    el('div', { class: 'side-by-side' },
      el('div', { class: 'half' }, el('h3', { text: 'Heat map: time spent per 1 m cell' }), labelled('Player', heatWho), heat, legend),
      el('div', { class: 'half' }, el('h3', { text: 'Per player (fieldvision stats)' }), table)),
    el('h3', { text: 'Export' }),
    el('section', { class: 'controls' }, labelled('Folder', exportOut),
      el('label', { title: 'a folder that is not empty is refused unless this is ticked; then an earlier export there is replaced and other files are kept' }, exportReplace, 'Replace an earlier export'), exportButton),
    el('p', { class: 'hint', text: 'Writes the statistics (players.csv, speed_profiles.csv, distances.csv, zone_alerts.csv, stats.json, index.html), the heat maps with their scales and the radar view as `fieldvision stats` makes them, and this page\'s heat map (with its scale), board, speed chart and zone alerts as page_*.png.' }),
    exportMsg,
  );

  let fmap: FieldMap | null = null;
  let frames: number[] = [];
  let byFrame = new Map<number, Player[]>();
  let times = new Map<number, number>();
  let timer = 0;
  let zones: Zone[] = [];
  let plot: uPlot | null = null;
  let model: api.FieldModel | null = null;
  let playerStats: PlayerStats | null = null;
  let teamOf = new Map<number, number>();

  const colourOf = (p: { id: number; team?: number | null }) =>
    p.team !== null && p.team !== undefined ? teamColours[p.team % teamColours.length] : `hsl(${(p.id * 67) % 360}, 80%, 60%)`;

  // ---- the video beside the board: one frame request at a time, the latest wanted next.
  let frameImage: HTMLImageElement | null = null;
  let shownFrame = -1;
  let wanted = -1;
  let loading = false;
  function drawVideo() {
    const ctx = videoCanvas.getContext('2d')!;
    if (!frameImage) {
      ctx.fillStyle = '#000';
      ctx.fillRect(0, 0, videoCanvas.width, videoCanvas.height);
      return;
    }
    ctx.drawImage(frameImage, 0, 0);
    const lw = Math.max(1, videoCanvas.width / 640);
    ctx.lineWidth = 2 * lw;
    ctx.font = `bold ${Math.round(12 * lw)}px sans-serif`;
    for (const p of byFrame.get(shownFrame + 1) ?? []) {
      if (!p.box) continue;
      ctx.strokeStyle = colourOf(p);
      ctx.strokeRect(p.box[0], p.box[1], p.box[2], p.box[3]);
      ctx.fillStyle = colourOf(p);
      ctx.fillText(String(p.id), p.box[0], p.box[1] - 3);
    }
  }
  async function fetchFrame() {
    if (loading || wanted < 0 || wanted === shownFrame || !video.value) return;
    loading = true;
    const f = wanted;
    try {
      const img = await api.loadFrame(video.value, f);
      if (videoCanvas.width !== img.naturalWidth || videoCanvas.height !== img.naturalHeight) {
        videoCanvas.width = img.naturalWidth;
        videoCanvas.height = img.naturalHeight;
      }
      frameImage = img;
      shownFrame = f;
      videoCanvas.dataset.frame = String(f);
      drawVideo();
    } catch (e) {
      status(msg, `video: ${(e as Error).message}`, true);
      wanted = -1;
    } finally {
      loading = false;
    }
    void fetchFrame();
  }

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
        ctx.fillStyle = colourOf(p);
        ctx.globalAlpha = 0.35;
        ctx.fillRect(x - 1.5, y - 1.5, 3, 3);
      }
    }
    ctx.globalAlpha = 1;
    ctx.font = 'bold 12px sans-serif';
    const now = byFrame.get(f) ?? [];
    for (const p of now) {
      const [x, y] = fmap.toCanvas(p.x, p.y);
      ctx.fillStyle = colourOf(p);
      ctx.beginPath();
      ctx.arc(x, y, 8, 0, 2 * Math.PI);
      ctx.fill();
      ctx.fillStyle = '#000';
      ctx.fillText(String(p.id), x - 4, y + 4);
    }
    timeLabel.textContent = ` t = ${t.toFixed(2)} s, frame ${f}, ${now.length} players`;
    board.dataset.frame = String(f);
    plot?.setCursor({ left: plot.valToPos(t, 'x'), top: 10 });
    drawAlerts(t);
    if (video.value) {
      wanted = f - 1;
      void fetchFrame();
    }
  }

  // Player positions by id: [time index, player] in time order.
  function byPlayer(): Map<number, [number, Player][]> {
    const m = new Map<number, [number, Player][]>();
    frames.forEach((f, i) => {
      for (const p of byFrame.get(f) ?? []) {
        if (!m.has(p.id)) m.set(p.id, []);
        m.get(p.id)!.push([i, p]);
      }
    });
    return m;
  }

  // Speed of each player (m/s) between frames, averaged over 5 steps; the 12 longest tracks.
  function speedChart(players: Map<number, [number, Player][]>) {
    plot?.destroy();
    plot = null;
    const t = frames.map((f) => times.get(f) ?? 0);
    const ids = [...players.keys()].sort((a, b) => players.get(b)!.length - players.get(a)!.length).slice(0, 12).sort((a, b) => a - b);
    const series: (number | null)[][] = ids.map((id) => {
      const track = new Map(players.get(id)!);
      const raw = t.map((_, i) => {
        const a = track.get(i - 1);
        const b = track.get(i);
        return a && b && t[i] > t[i - 1] ? Math.hypot(b.x - a.x, b.y - a.y) / (t[i] - t[i - 1]) : null;
      });
      const smooth = raw.map((_, i) => {
        const w = raw.slice(Math.max(0, i - 2), i + 3).filter((v): v is number => v !== null);
        return raw[i] === null || !w.length ? null : w.reduce((a, b) => a + b, 0) / w.length;
      });
      return smooth;
    });
    if (!t.length) return;
    plot = new uPlot({
      width: chart.clientWidth || 900, height: 190,
      series: [{ label: 't (s)' }, ...ids.map((id) => ({ label: `id ${id}`, stroke: `hsl(${(id * 67) % 360}, 80%, 60%)`, width: 1.2, points: { show: false } }))],
      axes: [{ label: 'time (s)', stroke: '#ccc' }, { label: 'speed (m/s)', stroke: '#ccc' }],
      scales: { x: { time: false } },
    }, [t, ...series] as uPlot.AlignedData, chart);
  }

  function statsTable() {
    const st = playerStats;
    if (!st) {
      table.replaceChildren();
      return;
    }
    const zoneNames = zones.map((z) => z.name);
    table.replaceChildren(
      el('tr', {}, ...['player', 'team', 'distance (m)', 'top speed (m/s, 1 s)', 'mean (m/s)', 'sprints', ...zoneNames.map((z) => `in ${z} (s)`)].map((h) => el('th', { text: h }))),
      ...st.players.map((p) => el('tr', { 'data-id': String(p.id), 'data-distance': String(p.distance_m) },
        el('td', { style: `color:${colourOf({ id: p.id, team: p.team >= 0 ? p.team : teamOf.get(p.id) ?? null })}`, text: `id ${p.id}` }),
        el('td', { text: p.team >= 0 ? String(p.team) : teamOf.has(p.id) ? String(teamOf.get(p.id)) : '–' }),
        el('td', { text: p.distance_m.toFixed(1) }), el('td', { text: p.top_speed_mps.toFixed(2) }), el('td', { text: p.mean_speed_mps.toFixed(2) }),
        el('td', { text: String(p.sprints) }), ...zoneNames.map((z) => el('td', { text: (p.zone_time_s[z] ?? 0).toFixed(1) })))),
    );
  }

  // Zone alerts: a row per zone, a bar per stay of a player (its colour and id), the board's time.
  // Each zone's stays in lanes: a stay goes to the first lane free by its start, so stays that
  // overlap (several players in one zone at once) are all seen, one above the other.
  function zoneLanes(zoneName: string): PlayerStats['events'][] {
    const lanes: PlayerStats['events'][] = [];
    const stays = (playerStats?.events ?? []).filter((ev) => ev.zone === zoneName).sort((a, b) => a.enter_s - b.enter_s);
    for (const e of stays) {
      const free = lanes.find((l) => l[l.length - 1].exit_s <= e.enter_s);
      if (free) free.push(e);
      else lanes.push([e]);
    }
    return lanes;
  }

  function drawAlerts(now: number) {
    const laneH = 16;
    const lanesOf = zones.map((z) => zoneLanes(z.name));
    const rowH = lanesOf.map((l) => 6 + laneH * Math.max(1, l.length));
    const h = 24 + Math.max(22, rowH.reduce((a, b) => a + b, 0));
    if (alerts.height !== h) alerts.height = h;
    const ctx = alerts.getContext('2d')!;
    ctx.fillStyle = '#111';
    ctx.fillRect(0, 0, alerts.width, alerts.height);
    const t = frames.map((f) => times.get(f) ?? 0);
    const t0 = t.length ? t[0] : 0;
    const t1 = t.length > 1 ? t[t.length - 1] : t0 + 1;
    const left = 110;
    const x = (s: number) => left + ((s - t0) / (t1 - t0 || 1)) * (alerts.width - left - 10);
    ctx.font = '12px sans-serif';
    if (!zones.length) {
      ctx.fillStyle = '#999';
      ctx.fillText('no zones file chosen', 8, 16);
    }
    const events = playerStats?.events ?? [];
    let y = 4;
    zones.forEach((z, k) => {
      ctx.fillStyle = '#ccc';
      ctx.fillText(z.name.slice(0, 14), 6, y + 14);
      ctx.fillStyle = '#222';
      ctx.fillRect(left, y, alerts.width - left - 10, rowH[k] - 4);
      lanesOf[k].forEach((lane, j) => {
        const ly = y + 1 + j * laneH;
        for (const e of lane) {
          ctx.fillStyle = colourOf({ id: e.id, team: teamOf.get(e.id) ?? null });
          ctx.globalAlpha = 0.8;
          ctx.fillRect(x(e.enter_s), ly + 1, Math.max(2, x(e.exit_s) - x(e.enter_s)), laneH - 3);
          ctx.globalAlpha = 1;
          ctx.fillStyle = '#000';
          ctx.fillText(String(e.id), x(e.enter_s) + 2, ly + 12);
        }
      });
      y += rowH[k];
    });
    // Time axis and the board's time.
    ctx.fillStyle = '#aaa';
    const axisY = alerts.height - 6;
    for (let k = 0; k <= 5; ++k) {
      const s = t0 + ((t1 - t0) * k) / 5;
      ctx.fillText(`${s.toFixed(1)} s`, x(s) - 10, axisY);
    }
    ctx.strokeStyle = '#ff0';
    ctx.beginPath();
    ctx.moveTo(x(now), 0);
    ctx.lineTo(x(now), alerts.height - 18);
    ctx.stroke();
    alerts.dataset.events = String(events.length);
  }

  // Heat map: seconds spent in each 1 m cell (each sample counts its frame's duration), drawn
  // over the field with a colour scale from 0 to the busiest cell.
  function drawHeat(players: Map<number, [number, Player][]>) {
    if (!model) return;
    const hm = new FieldMap(heat, model);
    const ctx = hm.draw();
    const cell = 1.0;
    const hl = model.length_m / 2 + model.surround_m;
    const hw = model.width_m / 2 + model.surround_m;
    const nx = Math.ceil((2 * hl) / cell);
    const ny = Math.ceil((2 * hw) / cell);
    const grid = new Float64Array(nx * ny);
    const t = frames.map((f) => times.get(f) ?? 0);
    const steps = t.slice(1).map((v, i) => v - t[i]).filter((d) => d > 0).sort((a, b) => a - b);
    const dt = steps.length ? steps[Math.floor(steps.length / 2)] : 0.04;
    const who = heatWho.value;
    for (const [id, samples] of players) {
      if (who !== 'all' && String(id) !== who) continue;
      for (const [, p] of samples) {
        const ix = Math.floor((p.x + hl) / cell);
        const iy = Math.floor((p.y + hw) / cell);
        if (ix >= 0 && iy >= 0 && ix < nx && iy < ny) grid[iy * nx + ix] += dt;
      }
    }
    const max = Math.max(...grid);
    for (let iy = 0; iy < ny; ++iy) {
      for (let ix = 0; ix < nx; ++ix) {
        const v = grid[iy * nx + ix];
        if (v <= 0) continue;
        const [r, g, b] = rampColour(v / max);
        ctx.fillStyle = `rgba(${Math.round(255 * r)}, ${Math.round(255 * g)}, ${Math.round(255 * b)}, 0.75)`;
        const [x0, y0] = hm.toCanvas(-hl + ix * cell, -hw + (iy + 1) * cell);
        ctx.fillRect(x0, y0, cell * hm.scale + 0.5, cell * hm.scale + 0.5);
      }
    }
    heat.dataset.maxS = max.toFixed(3);
    heat.dataset.totalS = grid.reduce((a, b) => a + b, 0).toFixed(3);
    // The colour scale.
    const lc = legend.getContext('2d')!;
    lc.fillStyle = '#161b22';
    lc.fillRect(0, 0, legend.width, legend.height);
    const x0 = 40;
    const w = legend.width - 200;
    for (let i = 0; i < w; ++i) {
      const [r, g, b] = rampColour(i / (w - 1));
      lc.fillStyle = `rgb(${Math.round(255 * r)}, ${Math.round(255 * g)}, ${Math.round(255 * b)})`;
      lc.fillRect(x0 + i, 6, 1, 14);
    }
    lc.fillStyle = '#ddd';
    lc.font = '12px sans-serif';
    for (let k = 0; k <= 4; ++k) {
      const x = x0 + (k * (w - 1)) / 4;
      lc.fillRect(x, 20, 1, 4);
      const label = `${((k * max) / 4).toFixed(max < 4 ? 2 : 1)} s`;
      lc.fillText(label, x - lc.measureText(label).width / 2, 38);
    }
    lc.fillText(`seconds per ${cell} m cell`, x0 + w + 12, 18);
  }

  load.onclick = async () => {
    try {
      const [f, tr] = await Promise.all([api.get<api.FieldModel>('/api/field', { name: field.value }), api.get<Tracks>('/api/tracks', { path: tracks.value })]);
      model = f;
      fmap = new FieldMap(board, f);
      byFrame = new Map();
      times = new Map();
      for (const r of tr.rows) {
        const [frame, id, l, top, w, h, x, y, t, team] = r as (number | null)[];
        if (x === null || y === null) continue;
        if (!byFrame.has(frame!)) byFrame.set(frame!, []);
        byFrame.get(frame!)!.push({ id: id!, x, y, box: l !== null && top !== null && w !== null && h !== null ? [l, top, w, h] : null, team: team ?? null });
        times.set(frame!, t ?? frame! / 25);
      }
      frames = [...byFrame.keys()].sort((a, b) => a - b);
      teamOf = new Map();
      for (const ps of byFrame.values()) for (const p of ps) if (p.team !== null) teamOf.set(p.id, p.team);
      zones = zonesFile.value ? await api.get<Zone[]>('/api/zones', { path: zonesFile.value }) : [];
      // The library's numbers (as `fieldvision stats`); the board plays without them.
      let statsNote = '';
      try {
        playerStats = await api.post<PlayerStats>('/api/players/stats', { tracks: tracks.value, ...(zonesFile.value ? { zones: zonesFile.value } : {}) });
      } catch (e) {
        playerStats = null;
        statsNote = `; no statistics: ${(e as Error).message}`;
      }
      statsTable();
      const players = byPlayer();
      heatWho.replaceChildren(el('option', { value: 'all', text: 'all players' }),
        ...[...players.keys()].sort((a, b) => a - b).map((id) => el('option', { value: String(id), text: `id ${id}` })));
      heatWho.onchange = () => drawHeat(players);
      speedChart(players);
      drawHeat(players);
      frameImage = null;
      shownFrame = -1;
      drawVideo();
      time.max = String(Math.max(0, frames.length - 1));
      time.value = '0';
      draw(0);
      // Positions beyond the map (the field and its surround) are not drawn: said, with the field.
      let off = 0, placed = 0;
      for (const ps of byFrame.values()) {
        for (const p of ps) {
          placed++;
          if (Math.abs(p.x) > f.length_m / 2 + f.surround_m || Math.abs(p.y) > f.width_m / 2 + f.surround_m) off++;
        }
      }
      const offNote = off ? `; ${off} of ${placed} positions lie beyond the ${f.name} map (not drawn): is it the field they were tracked on?` : '';
      status(msg, frames.length ? `${tr.rows.length} rows, ${frames.length} frames with field positions, ${players.size} players${statsNote}${offNote}` : 'no field positions (x_m, y_m) in this file: track with a calibrated camera', !frames.length);
    } catch (e) {
      status(msg, (e as Error).message, true);
    }
  };
  // The heat map as shown (one player or all) with its colour scale and a title, as one image.
  function heatImage(): HTMLCanvasElement {
    const title = 28;
    const c = el('canvas', { width: String(heat.width), height: String(title + heat.height + legend.height) });
    const ctx = c.getContext('2d')!;
    ctx.fillStyle = '#161b22';
    ctx.fillRect(0, 0, c.width, c.height);
    ctx.fillStyle = '#ddd';
    ctx.font = '15px sans-serif';
    const who = heatWho.value === 'all' ? 'all players' : `player ${heatWho.value}`;
    ctx.fillText(`Time spent per 1 m cell: ${who}, ${tracks.value}`, 8, 19);
    ctx.drawImage(heat, 0, title);
    ctx.drawImage(legend, 0, title + heat.height);
    return c;
  }

  exportButton.onclick = async () => {
    if (!model || !frames.length) {
      status(exportMsg, 'nothing to export: show a tracks file first', true);
      return;
    }
    try {
      status(exportMsg, 'exporting…');
      const images: Record<string, string> = { heatmap: heatImage().toDataURL('image/png'), board: board.toDataURL('image/png'), zone_alerts: alerts.toDataURL('image/png') };
      const speed = chart.querySelector('canvas');
      if (speed) images.speed = speed.toDataURL('image/png');
      const r = await api.post<{ wrote: string[]; notes: string[] }>('/api/players/export', {
        tracks: tracks.value, field: field.value, out: exportOut.value, replace: exportReplace.checked, images, ...(zonesFile.value ? { zones: zonesFile.value } : {}),
      });
      exportMsg.dataset.wrote = JSON.stringify(r.wrote);
      status(exportMsg, `wrote ${r.wrote.length} files: ${r.wrote.join(', ')}${r.notes.length ? ` (${r.notes.join('; ')})` : ''}`);
    } catch (e) {
      status(exportMsg, (e as Error).message, true);
    }
  };
  time.addEventListener('input', () => draw(Number(time.value)));
  // Real time: the tracks' own frame step (the median; PETS at 7-10 fps played 2.7 s a second
  // at a fixed 40 ms).
  const frameStepMs = () => {
    const t = frames.map((f) => times.get(f) ?? 0);
    const steps = t.slice(1).map((v, i) => v - t[i]).filter((d) => d > 0).sort((a, b) => a - b);
    return steps.length ? Math.max(15, 1000 * steps[Math.floor(steps.length / 2)]) : 40;
  };
  play.onclick = () => {
    if (timer) {
      clearInterval(timer);
      timer = 0;
      play.textContent = '▶ Play';
      return;
    }
    play.textContent = '❚❚ Pause';
    timer = window.setInterval(() => {
      if (!board.isConnected) {
        clearInterval(timer);
        return;
      }
      const i = (Number(time.value) + 1) % Math.max(1, frames.length);
      time.value = String(i);
      draw(i);
    }, frameStepMs());
  };
}
