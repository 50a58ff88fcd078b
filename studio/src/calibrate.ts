// Calibrate: open a frame of a camera's video, pick a field keypoint (list or field map), click
// it in the image (zoom loupe follows the pointer); with 4+ points the server estimates the pose
// (calib/extrinsics.h) and the page shows residuals in px and mm and the field lines reprojected.
// "Refine with lines" moves that pose so that the frame's painted lines fall on the field model's
// (calib/lines.h): line pixels found (green), line error before and after; saving then writes the
// refined pose. "Intrinsics from board images" calibrates a camera from chessboard or ChArUco
// views (calib/intrinsics.h) with each view's error and the views dropped.
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

interface LineStats {
  num_pixels: number;
  num_inliers: number;
  mean_mm: number;
  median_mm: number;
  p95_mm: number;
}

interface RefineResult {
  accepted: boolean;
  status: string;
  before: LineStats;
  after: LineStats;
  num_line_pixels: number;
  moved_m: number;
  rotated_deg: number;
  camera_position_m: number[];
  line_pixels: number[][];
  lines_px: number[][][];
  summary: string;
  wrote: string[];
}

interface IntrinsicsResult {
  camera: api.CameraJson & { distortion: number[] };
  rms_px: number;
  num_images: number;
  num_found: number;
  num_used: number;
  views: { name: string; board_found: boolean; num_corners: number; rms_px: number; used: boolean; dropped_because: string }[];
  std_px: number[];
  warnings: string[];
  summary: string;
  wrote: string[];
}

export async function calibratePage(root: HTMLElement): Promise<void> {
  const [list, info] = await Promise.all([api.files(), api.info()]);
  const video = fileSelect('cal-video', list, ['video', 'images', 'image']);
  const frame = el('input', { id: 'cal-frame', type: 'number', value: '0', min: '0' });
  const camera = fileSelect('cal-camera', list, ['camera']);
  const field = optionsSelect('cal-field', info.fields, 'robocup-msl');
  const load = el('button', { id: 'cal-load', text: 'Open frame' });
  const out = el('input', { id: 'cal-out', value: '' });
  const save = el('button', { id: 'cal-save', text: 'Save camera file' });
  const undo = el('button', { id: 'cal-undo', text: 'Remove last point' });
  const refine = el('button', { id: 'cal-refine', text: 'Refine with lines' });
  const refineResult = el('div', { id: 'cal-refine-result' });
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
      el('div', { class: 'main-view' }, image, msg, result, refineResult, table),
      el('div', { class: 'side' }, el('h3', { text: 'Keypoint to click' }), map, keypointList,
        el('h3', { text: 'Loupe (6x)' }), loupe, el('p', {}, refine, ' ', undo), el('p', {}, labelled('Save as', out)), save)),
    intrinsicsSection(list),
  );

  let img: HTMLImageElement | null = null;
  let model: api.FieldModel | null = null;
  let fmap: FieldMap | null = null;
  let clicks: Click[] = [];
  let selected = '';
  let pose: PoseResult | null = null;
  let refined: RefineResult | null = null;
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
    if (refined) {
      ctx.fillStyle = 'rgba(0, 255, 80, 0.8)';
      for (const [u, v] of refined.line_pixels) ctx.fillRect(u, v, lw, lw);
      ctx.strokeStyle = 'rgba(255, 120, 0, 0.95)';
      ctx.lineWidth = lw;
      for (const line of refined.lines_px) {
        ctx.beginPath();
        line.forEach(([u, v], i) => (i ? ctx.lineTo(u + 0.5, v + 0.5) : ctx.moveTo(u + 0.5, v + 0.5)));
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

  function showRefined() {
    if (!refined) {
      refineResult.replaceChildren();
      return;
    }
    const r = refined;
    const p = r.camera_position_m.map((v) => v.toFixed(3)).join(', ');
    refineResult.replaceChildren(
      el('div', {
        id: 'cal-refine-summary', 'data-accepted': r.accepted ? '1' : '0', 'data-before-mm': String(r.before.mean_mm), 'data-after-mm': String(r.after.mean_mm),
        'data-position': JSON.stringify(r.camera_position_m),
        text: r.accepted
          ? `refined against ${r.num_line_pixels} line pixels: line error mean ${r.before.mean_mm.toFixed(1)} → ${r.after.mean_mm.toFixed(1)} mm, median ${r.before.median_mm.toFixed(1)} → ${r.after.median_mm.toFixed(1)} mm, p95 ${r.before.p95_mm.toFixed(1)} → ${r.after.p95_mm.toFixed(1)} mm; camera moved ${(1000 * r.moved_m).toFixed(0)} mm, turned ${r.rotated_deg.toFixed(2)}°, now at (${p}) m`
          : `not refined: ${r.status} (line error mean ${r.before.mean_mm.toFixed(1)} mm over ${r.num_line_pixels} line pixels)`,
      }),
      el('div', { class: 'hint', text: r.accepted
        ? 'green: line pixels found in the frame; orange: the field lines at the refined pose. Saving writes the refined pose.'
        : 'green: line pixels found in the frame; orange: the field lines at the clicked pose. Saving writes the pose from the clicks.' }),
    );
  }

  async function solve() {
    const id = ++requestId;
    refined = null;
    showRefined();
    if (clicks.length < 4) {
      pose = null;
      showPose();
      status(msg, `${clicks.length} point(s): click at least 4 keypoints (not all on one line) for a pose`);
      draw();
      return;
    }
    try {
      // A camera file of another size than the frame (another camera's) gives no pose: said as
      // such (an encoder's padding, under 16 px, is fitted by the server).
      const cam = await api.get<api.CameraJson>('/api/camera', { path: camera.value });
      if (id !== requestId) return;
      if (img && (Math.abs(cam.width - img.naturalWidth) >= 16 || Math.abs(cam.height - img.naturalHeight) >= 16)) {
        pose = null;
        status(msg, `camera file ${camera.value} is for ${cam.width}x${cam.height} images but the frame is ${img.naturalWidth}x${img.naturalHeight}: choose this video's camera file`, true);
        showPose();
        draw();
        return;
      }
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
  const refineBody = () => ({
    camera: camera.value, field: field.value, video: video.value, frame: Number(frame.value),
    ...(clicks.length >= 4 ? { points: clicks } : {}),
  });
  refine.onclick = async () => {
    if (!img) return;
    try {
      status(msg, 'refining against the painted lines…');
      const r = await api.post<RefineResult>('/api/calibrate/refine', refineBody());
      refined = r;
      showRefined();
      draw();
      status(msg, r.accepted ? 'pose refined against the lines' : `not refined: ${r.status}`, !r.accepted);
    } catch (e) {
      status(msg, (e as Error).message, true);
    }
  };
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
      refined = null;
      showRefined();
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
      if (refined?.accepted) {
        const r = await api.postSave<RefineResult>('/api/calibrate/refine', { ...refineBody(), out: out.value });
        refined = r;
        showRefined();
        draw();
        status(msg, r.wrote.length ? `wrote ${r.wrote.join(', ')} (refined against the lines)` : `not written: ${r.status}`, !r.wrote.length);
        return;
      }
      const r = await api.postSave<PoseResult>('/api/calibrate/save', {
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

// Intrinsics from board images: a folder, a pattern (dir/left*.jpg) or a video of the folder.
function intrinsicsSection(list: api.FileEntry[]): HTMLElement {
  const folders = [...new Set(list.filter((f) => f.kind === 'image').map((f) => f.path.replace(/[^/]*$/, '')))];
  const images = el('input', { id: 'int-images', size: '28', value: folders.length ? `${folders[0]}*.${list.find((f) => f.kind === 'image')!.path.split('.').pop()}` : '' });
  const type = optionsSelect('int-board', ['chessboard', 'charuco'], 'chessboard');
  const cols = el('input', { id: 'int-cols', type: 'number', value: '9', min: '2', style: 'width:4em' });
  const rows = el('input', { id: 'int-rows', type: 'number', value: '6', min: '2', style: 'width:4em' });
  const square = el('input', { id: 'int-square', type: 'number', value: '25', min: '0.1', step: '0.1', style: 'width:5em' });
  const dist = optionsSelect('int-distortion', ['4', '5', '8'], '5');
  const out = el('input', { id: 'int-out', value: 'intrinsics.yaml' });
  const run = el('button', { id: 'int-run', text: 'Calibrate intrinsics' });
  const msg = el('div', { id: 'int-status', class: 'status' });
  const table = el('table', { id: 'int-views' });
  const chart = el('canvas', { id: 'int-chart', width: '600', height: '140' });
  run.onclick = async () => {
    try {
      status(msg, 'finding the board in every image and calibrating…');
      table.replaceChildren();
      const r = await api.postSave<IntrinsicsResult>('/api/calibrate/intrinsics', {
        images: images.value, num_distortion: Number(dist.value), out: out.value || undefined,
        board: { type: type.value, cols: Number(cols.value), rows: Number(rows.value), square_m: Number(square.value) / 1000 },
      });
      const c = r.camera;
      status(msg, `fx ${c.fx.toFixed(1)} fy ${c.fy.toFixed(1)} cx ${c.cx.toFixed(1)} cy ${c.cy.toFixed(1)} px (± ${r.std_px.map((v) => v.toFixed(1)).join(', ')}), ` +
        `RMS ${r.rms_px.toFixed(3)} px over ${r.num_used} of ${r.num_images} views (${r.num_found} with the board)` +
        `${r.warnings.length ? '; ' + r.warnings.join('; ') : ''}${r.wrote.length ? '; wrote ' + r.wrote.join(', ') : ''}`);
      // Done, but with warnings (few views, a board only in the middle): not in the success colour.
      if (r.warnings.length) msg.classList.add('warn');
      msg.dataset.fx = String(c.fx);
      table.replaceChildren(
        el('tr', {}, ...['view', 'board', 'corners', 'error px', ''].map((h) => el('th', { text: h }))),
        ...r.views.map((v) => el('tr', { class: v.used ? '' : 'outlier', 'data-view': v.name, 'data-rms': String(v.rms_px) },
          el('td', { text: v.name }), el('td', { text: v.board_found ? 'found' : 'not found' }), el('td', { text: String(v.num_corners) }),
          el('td', { text: v.board_found ? v.rms_px.toFixed(3) : '–' }), el('td', { text: v.used ? '' : v.dropped_because || 'not used' }))),
      );
      // Per-view errors as bars (dropped views in magenta), the overall RMS as a line.
      const ctx = chart.getContext('2d')!;
      ctx.fillStyle = '#111';
      ctx.fillRect(0, 0, chart.width, chart.height);
      const found = r.views.filter((v) => v.board_found);
      const top = Math.max(r.rms_px * 2, ...found.map((v) => v.rms_px)) || 1;
      const w = chart.width / Math.max(1, found.length);
      found.forEach((v, i) => {
        const h = ((chart.height - 20) * v.rms_px) / top;
        ctx.fillStyle = v.used ? '#4af' : '#f4f';
        ctx.fillRect(i * w + 2, chart.height - h, w - 4, h);
      });
      const y = chart.height - ((chart.height - 20) * r.rms_px) / top;
      ctx.strokeStyle = '#fc0';
      ctx.beginPath();
      ctx.moveTo(0, y);
      ctx.lineTo(chart.width, y);
      ctx.stroke();
      ctx.fillStyle = '#fc0';
      ctx.font = '11px sans-serif';
      ctx.fillText(`RMS ${r.rms_px.toFixed(3)} px (scale: 0–${top.toFixed(2)} px)`, 4, 12);
    } catch (e) {
      status(msg, (e as Error).message, true);
    }
  };
  return el('section', { id: 'int-section' }, el('h3', { text: 'Intrinsics from board images' }),
    el('div', { class: 'controls' }, labelled('Images (folder, dir/*.jpg or video)', images), labelled('Board', type), labelled('Inner corners per row', cols),
      labelled('per column', rows), labelled('Square (mm)', square), labelled('Distortion terms', dist), labelled('Save as', out), run),
    msg, chart, table);
}
