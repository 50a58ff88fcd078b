// Calibrate: open a frame of a camera's video, pick a field keypoint (list or field map), click
// it in the image (zoom loupe follows the pointer); with 4+ points the server estimates the pose
// (calib/extrinsics.h) and the page shows residuals in px and mm and the field lines reprojected.
import * as api from './api';
import { el, fileSelect, optionsSelect, labelled, status, FieldMap } from './ui';

interface Click {
  name: string;
  u: number;
  v: number;
}

interface PoseResult {
  rms_px: number;
  max_err_px: number;
  mean_err_mm: number;
  num_inliers: number;
  camera_position_m: number[];
  points: { name: string; u: number; v: number; projected: number[]; err_px: number; err_mm: number | null; inlier: boolean }[];
  lines_px: number[][][];
  keypoints_px: { name: string; u: number; v: number }[];
  wrote?: string[];
}

export async function calibratePage(root: HTMLElement): Promise<void> {
  const [list, info] = await Promise.all([api.files(), api.info()]);
  const video = fileSelect('cal-video', list, ['video', 'images']);
  const frame = el('input', { id: 'cal-frame', type: 'number', value: '0', min: '0' });
  const camera = fileSelect('cal-camera', list, ['camera']);
  const field = optionsSelect('cal-field', info.fields, 'robocup-msl');
  const load = el('button', { id: 'cal-load', text: 'Open frame' });
  const out = el('input', { id: 'cal-out', value: '' });
  const save = el('button', { id: 'cal-save', text: 'Save camera file' });
  const undo = el('button', { id: 'cal-undo', text: 'Remove last point' });
  const msg = el('div', { id: 'cal-status', class: 'status' });
  const image = el('canvas', { id: 'cal-image', class: 'frame' });
  const loupe = el('canvas', { id: 'cal-loupe', width: '180', height: '180' });
  const map = el('canvas', { id: 'cal-map', width: '360', height: '260' });
  const keypointList = el('div', { id: 'cal-keypoints', class: 'keypoints' });
  const result = el('div', { id: 'cal-result' });
  const table = el('table', { id: 'cal-points' });
  const suggestOut = () => {
    out.value = camera.value.replace(/(\.ya?ml)?$/i, '_studio.yaml');
  };
  camera.onchange = suggestOut;
  suggestOut();

  root.replaceChildren(
    el('section', { class: 'controls' }, labelled('Video', video), labelled('Frame', frame),
      labelled('Camera (intrinsics)', camera), labelled('Field', field), load),
    el('div', { class: 'workspace' },
      el('div', { class: 'main-view' }, image, msg, result, table),
      el('div', { class: 'side' }, el('h3', { text: 'Keypoint to click' }), map, keypointList,
        el('h3', { text: 'Loupe (6x)' }), loupe, el('p', {}, labelled('Save as', out)), save, undo)),
  );

  let img: HTMLImageElement | null = null;
  let model: api.FieldModel | null = null;
  let fmap: FieldMap | null = null;
  let clicks: Click[] = [];
  let selected = '';
  let pose: PoseResult | null = null;
  let pointer: [number, number] | null = null;
  let requestId = 0;

  const toImage = (e: PointerEvent): [number, number] => {
    const s = image.width / image.clientWidth;
    return [e.offsetX * s - 0.5, e.offsetY * s - 0.5];
  };

  const selectKeypoint = (name: string) => {
    selected = name;
    for (const b of keypointList.querySelectorAll('button')) {
      b.classList.toggle('selected', b.dataset.keypoint === name);
      b.classList.toggle('done', clicks.some((c) => c.name === b.dataset.keypoint));
    }
    drawMap();
  };

  const nextKeypoint = () => {
    const next = model?.keypoints.find((k) => !clicks.some((c) => c.name === k.name));
    selectKeypoint(next ? next.name : '');
  };

  function drawMap() {
    if (!fmap || !model) return;
    const ctx = fmap.draw();
    for (const k of model.keypoints) {
      const [x, y] = fmap.toCanvas(k.position_m[0], k.position_m[1]);
      const done = clicks.some((c) => c.name === k.name);
      ctx.fillStyle = k.name === selected ? '#ff0' : done ? '#0cf' : '#fff';
      ctx.beginPath();
      ctx.arc(x, y, k.name === selected ? 6 : 4, 0, 2 * Math.PI);
      ctx.fill();
    }
    if (selected) {
      ctx.fillStyle = '#ff0';
      ctx.font = '13px sans-serif';
      ctx.fillText(selected, 8, 16);
    }
  }

  function draw() {
    if (!img) return;
    const ctx = image.getContext('2d')!;
    ctx.drawImage(img, 0, 0);
    const lw = Math.max(1, image.width / 800);
    if (pose) {
      ctx.strokeStyle = 'rgba(255, 230, 0, 0.9)';
      ctx.lineWidth = lw;
      for (const line of pose.lines_px) {
        ctx.beginPath();
        line.forEach(([u, v], i) => (i ? ctx.lineTo(u + 0.5, v + 0.5) : ctx.moveTo(u + 0.5, v + 0.5)));
        ctx.stroke();
      }
      for (const p of pose.points) {
        ctx.strokeStyle = p.inlier ? '#0ff' : '#f0f';
        ctx.beginPath();
        ctx.arc(p.projected[0] + 0.5, p.projected[1] + 0.5, 4 * lw, 0, 2 * Math.PI);
        ctx.moveTo(p.u + 0.5, p.v + 0.5);
        ctx.lineTo(p.projected[0] + 0.5, p.projected[1] + 0.5);
        ctx.stroke();
      }
    }
    ctx.font = `${Math.round(12 * lw)}px sans-serif`;
    clicks.forEach((c, i) => {
      ctx.strokeStyle = '#f33';
      ctx.lineWidth = lw;
      const r = 6 * lw;
      ctx.beginPath();
      ctx.moveTo(c.u + 0.5 - r, c.v + 0.5);
      ctx.lineTo(c.u + 0.5 + r, c.v + 0.5);
      ctx.moveTo(c.u + 0.5, c.v + 0.5 - r);
      ctx.lineTo(c.u + 0.5, c.v + 0.5 + r);
      ctx.stroke();
      ctx.fillStyle = '#f33';
      ctx.fillText(String(i + 1), c.u + r, c.v - r);
    });
    drawLoupe();
  }

  function drawLoupe() {
    const ctx = loupe.getContext('2d')!;
    ctx.fillStyle = '#222';
    ctx.fillRect(0, 0, loupe.width, loupe.height);
    if (!pointer || !img) return;
    const zoom = 6;
    const half = loupe.width / zoom / 2;
    const [x0, y0] = [pointer[0] + 0.5 - half, pointer[1] + 0.5 - half];
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(img, x0, y0, 2 * half, 2 * half, 0, 0, loupe.width, loupe.height);
    // Clicked points (red) and reprojected keypoints (cyan) near the pointer.
    const mark = (u: number, v: number, colour: string) => {
      const [x, y] = [(u + 0.5 - x0) * zoom, (v + 0.5 - y0) * zoom];
      ctx.strokeStyle = colour;
      ctx.strokeRect(x - 4, y - 4, 8, 8);
    };
    for (const c of clicks) mark(c.u, c.v, '#f33');
    for (const p of pose?.points ?? []) mark(p.projected[0], p.projected[1], '#0ff');
    ctx.strokeStyle = '#0f0';
    ctx.beginPath();
    ctx.moveTo(loupe.width / 2, 0);
    ctx.lineTo(loupe.width / 2, loupe.height);
    ctx.moveTo(0, loupe.height / 2);
    ctx.lineTo(loupe.width, loupe.height / 2);
    ctx.stroke();
    ctx.fillStyle = '#0f0';
    ctx.fillText(`${pointer[0].toFixed(1)}, ${pointer[1].toFixed(1)} px`, 4, 12);
  }

  function showPose() {
    if (!pose) {
      result.replaceChildren();
      table.replaceChildren();
      return;
    }
    const p = pose.camera_position_m.map((v) => v.toFixed(3)).join(', ');
    result.replaceChildren(
      el('span', { id: 'cal-rms', text: `RMS ${pose.rms_px.toFixed(2)} px` }),
      el('span', { text: ` · max ${pose.max_err_px.toFixed(2)} px · mean ${pose.mean_err_mm.toFixed(1)} mm on the field · ${pose.num_inliers}/${pose.points.length} inliers · ` }),
      el('span', { id: 'cal-position', 'data-position': JSON.stringify(pose.camera_position_m), text: `camera at (${p}) m` }),
    );
    table.replaceChildren(
      el('tr', {}, ...['#', 'keypoint', 'u px', 'v px', 'error px', 'error mm', ''].map((h) => el('th', { text: h }))),
      ...pose.points.map((q, i) =>
        el('tr', { class: q.inlier ? '' : 'outlier' },
          el('td', { text: String(i + 1) }), el('td', { text: q.name }), el('td', { text: q.u.toFixed(1) }),
          el('td', { text: q.v.toFixed(1) }), el('td', { text: q.err_px.toFixed(2) }),
          el('td', { text: q.err_mm === null ? '–' : q.err_mm.toFixed(1) }), el('td', { text: q.inlier ? '' : 'outlier' }))),
    );
  }

  async function solve() {
    const id = ++requestId;
    if (clicks.length < 4) {
      pose = null;
      showPose();
      status(msg, `${clicks.length} point(s): click at least 4 keypoints (not all on one line) for a pose`);
      draw();
      return;
    }
    try {
      const r = await api.post<PoseResult>('/api/calibrate/pose', { camera: camera.value, field: field.value, points: clicks });
      if (id !== requestId) return;
      pose = r;
      status(msg, `pose from ${clicks.length} points`);
    } catch (e) {
      if (id !== requestId) return;
      pose = null;
      status(msg, (e as Error).message, true);
    }
    showPose();
    draw();
  }

  image.addEventListener('pointermove', (e) => {
    pointer = toImage(e);
    drawLoupe();
  });
  image.addEventListener('pointerdown', (e) => {
    if (!img || !selected) {
      if (img) status(msg, 'pick a keypoint first (list or field map)', true);
      return;
    }
    const [u, v] = toImage(e);
    clicks = clicks.filter((c) => c.name !== selected);
    clicks.push({ name: selected, u, v });
    nextKeypoint();
    draw();
    void solve();
  });
  map.addEventListener('pointerdown', (e) => {
    if (!fmap || !model) return;
    let best = '';
    let bestD = 15;
    for (const k of model.keypoints) {
      const [x, y] = fmap.toCanvas(k.position_m[0], k.position_m[1]);
      const d = Math.hypot(x - e.offsetX * (map.width / map.clientWidth), y - e.offsetY * (map.height / map.clientHeight));
      if (d < bestD) [best, bestD] = [k.name, d];
    }
    if (best) selectKeypoint(best);
  });
  undo.onclick = () => {
    clicks.pop();
    nextKeypoint();
    void solve();
  };

  load.onclick = async () => {
    try {
      status(msg, 'loading…');
      const [frameImg, f] = await Promise.all([api.loadFrame(video.value, Number(frame.value)), api.get<api.FieldModel>('/api/field', { name: field.value })]);
      img = frameImg;
      model = f;
      image.width = img.naturalWidth;
      image.height = img.naturalHeight;
      fmap = new FieldMap(map, model);
      keypointList.replaceChildren(
        ...model.keypoints.map((k) => {
          const b = el('button', { 'data-keypoint': k.name, text: k.name, title: k.position_m.map((v) => v.toFixed(2)).join(', ') + ' m' });
          b.onclick = () => selectKeypoint(k.name);
          return b;
        }),
      );
      clicks = [];
      pose = null;
      nextKeypoint();
      draw();
      await solve();
      image.dataset.ready = '1';
    } catch (e) {
      status(msg, (e as Error).message, true);
    }
  };
  save.onclick = async () => {
    try {
      const r = await api.post<PoseResult>('/api/calibrate/save', {
        camera: camera.value, field: field.value, points: clicks, out: out.value,
        points_out: out.value.replace(/(\.ya?ml)?$/i, '_points.csv'),
      });
      pose = r;
      showPose();
      draw();
      status(msg, `wrote ${r.wrote?.join(', ')}`);
    } catch (e) {
      status(msg, (e as Error).message, true);
    }
  };
}
