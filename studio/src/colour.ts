// Ball colour: click on the ball (shift-click: not the ball) or drag a box around it, on one
// frame or several (a new frame keeps the earlier frames' clicks: lights and white balance
// differ); the server learns an HSV box (detect/colour_learn.h) that the sliders show and edit,
// the selected pixels are shown live over the frame, the colour file is saved and the detector
// run on a few frames.
import * as api from './api';
import { el, fileSelect, labelled, status } from './ui';

type Range = { space: string; min: number[]; max: number[] };
type Clicks = { frame: number; points: number[][]; negative_points: number[][]; roi?: number[] };

interface DetectResult {
  frames: { frame: number; candidates: { u: number; v: number; radius_px: number; score: number; accepted: boolean }[] }[];
}

// HSV as OpenCV's COLOR_BGR2HSV_FULL then scaled to degrees (detect/colour.cc BgrToHsv).
export function hsvOf(r: number, g: number, b: number): [number, number, number] {
  const max = Math.max(r, g, b);
  const min = Math.min(r, g, b);
  const d = max - min;
  let h = 0;
  if (d > 0) {
    if (max === r) h = (60 * (g - b)) / d;
    else if (max === g) h = 120 + (60 * (b - r)) / d;
    else h = 240 + (60 * (r - g)) / d;
    if (h < 0) h += 360;
  }
  const h8 = Math.round((h * 256) / 360) & 255;
  return [(h8 * 360) / 256, max ? Math.round((255 * d) / max) : 0, max];
}

export function inRange(range: Range, h: number, s: number, v: number): boolean {
  const [h0, s0, v0] = range.min;
  const [h1, s1, v1] = range.max;
  const hueIn = h0 <= h1 ? h >= h0 && h <= h1 : h >= h0 || h <= h1;
  return hueIn && s >= s0 && s <= s1 && v >= v0 && v <= v1;
}

export async function colourPage(root: HTMLElement): Promise<void> {
  const list = await api.files();
  const video = fileSelect('col-video', list, ['video', 'images', 'image']);
  const frame = el('input', { id: 'col-frame', type: 'number', value: '0', min: '0' });
  const load = el('button', { id: 'col-load', text: 'Open frame' });
  const clear = el('button', { id: 'col-clear', text: 'Clear clicks' });
  const image = el('canvas', { id: 'col-image', class: 'frame' });
  const msg = el('div', { id: 'col-status', class: 'status' });
  const out = el('input', { id: 'col-out', value: 'ball_colour.json' });
  const save = el('button', { id: 'col-save', text: 'Save colour file' });
  const detectFrames = el('input', { id: 'col-detect-frames', value: '0' });
  const detect = el('button', { id: 'col-detect', text: 'Run detect' });
  const detectResult = el('div', { id: 'col-detect-result' });
  const count = el('div', { id: 'col-count' });
  const sliders: HTMLInputElement[] = [];
  const sliderRows: HTMLElement[] = [];
  const names = ['hue', 'saturation', 'value'];
  for (let ch = 0; ch < 3; ++ch) {
    for (const end of ['min', 'max']) {
      const s = el('input', { id: `col-${names[ch][0]}${end}`, type: 'range', min: '0', max: ch ? '255' : '360', step: '1', value: end === 'min' ? '0' : ch ? '255' : '360' });
      const shown = el('span', { class: 'value' });
      s.addEventListener('input', () => {
        shown.textContent = s.value;
        range = rangeFromSliders();
        drawOverlay();
      });
      sliders.push(s);
      sliderRows.push(labelled(`${names[ch]} ${end}${ch ? '' : ' (°)'}`, el('span', {}, s, shown)));
    }
  }

  root.replaceChildren(
    el('section', { class: 'controls' }, labelled('Video', video), labelled('Frame', frame), load, clear),
    el('div', { class: 'workspace' },
      el('div', { class: 'main-view' }, image, msg, count),
      el('div', { class: 'side' }, el('p', { class: 'hint', text: 'Click on the ball (shift-click: not the ball) or drag a box around it; open another frame to add its clicks.' }),
        ...sliderRows, el('p', {}, labelled('Save as', out)), save,
        el('h3', { text: 'Check: run the detector' }), labelled('Frames', detectFrames), detect, detectResult)),
  );

  let img: HTMLImageElement | null = null;
  let pixels: ImageData | null = null;
  let hsv: Float32Array | null = null;
  let range: Range | null = null;
  let points: number[][] = [];
  let negatives: number[][] = [];
  let roi: number[] | null = null;
  let shownFrame = 0;
  // Clicks on frames opened before this one, learned together with this frame's.
  let kept: Clicks[] = [];
  let drag: [number, number] | null = null;
  let dragNow: [number, number] | null = null;
  let found: { u: number; v: number; radius_px: number; accepted: boolean }[] = [];
  let saved = '';
  let savedRange = '';  // the sliders' range when `saved` was written
  // Learn requests sent and answered: a click sends one; only the newest answer is applied (an
  // older one arriving late would undo a later click), and #col-status's data-learned counts the
  // answers so a caller can wait for all of them.
  let learnSent = 0;
  let learnAnswered = 0;

  const rangeFromSliders = (): Range => ({
    space: 'hsv',
    min: [0, 2, 4].map((i) => Number(sliders[i].value)),
    max: [1, 3, 5].map((i) => Number(sliders[i].value)),
  });
  const setSliders = (r: Range) => {
    [r.min[0], r.max[0], r.min[1], r.max[1], r.min[2], r.max[2]].forEach((v, i) => {
      sliders[i].value = String(Math.round(v));
      (sliders[i].nextSibling as HTMLElement).textContent = sliders[i].value;
    });
  };
  const toImage = (e: PointerEvent): [number, number] => {
    const s = image.width / image.clientWidth;
    return [e.offsetX * s - 0.5, e.offsetY * s - 0.5];
  };

  function drawOverlay() {
    if (!img || !pixels || !hsv) return;
    const ctx = image.getContext('2d')!;
    const outData = new ImageData(new Uint8ClampedArray(pixels.data), pixels.width, pixels.height);
    const d = outData.data;
    let selected = 0;
    if (range) {
      for (let i = 0, n = pixels.width * pixels.height; i < n; ++i) {
        if (inRange(range, hsv[3 * i], hsv[3 * i + 1], hsv[3 * i + 2])) {
          ++selected;
          d[4 * i] = 255;
          d[4 * i + 1] = 0;
          d[4 * i + 2] = 255;
        } else {
          d[4 * i] *= 0.45;
          d[4 * i + 1] *= 0.45;
          d[4 * i + 2] *= 0.45;
        }
      }
    }
    ctx.putImageData(outData, 0, 0);
    count.textContent = range ? `${selected} pixels selected (magenta) of ${pixels.width * pixels.height}` : '';
    count.dataset.selected = String(selected);
    const lw = Math.max(1, image.width / 800);
    ctx.lineWidth = lw;
    for (const [u, v] of points) {
      ctx.strokeStyle = '#0f0';
      ctx.strokeRect(u - 3 * lw, v - 3 * lw, 6 * lw + 1, 6 * lw + 1);
    }
    for (const [u, v] of negatives) {
      ctx.strokeStyle = '#f00';
      ctx.strokeRect(u - 3 * lw, v - 3 * lw, 6 * lw + 1, 6 * lw + 1);
    }
    const box = drag && dragNow ? [drag[0], drag[1], dragNow[0] - drag[0], dragNow[1] - drag[1]] : roi;
    if (box) {
      ctx.strokeStyle = '#0f0';
      ctx.strokeRect(box[0], box[1], box[2], box[3]);
    }
    for (const c of found) {
      ctx.strokeStyle = c.accepted ? '#0ff' : '#888';
      ctx.beginPath();
      ctx.arc(c.u + 0.5, c.v + 0.5, c.radius_px + 2 * lw, 0, 2 * Math.PI);
      ctx.stroke();
    }
  }

  const clicksHere = (): Clicks => ({ frame: shownFrame, points, negative_points: negatives, ...(roi ? { roi } : {}) });

  async function learn() {
    drawOverlay();
    if (!points.length && !roi) return;
    const seq = ++learnSent;
    const here = clicksHere();
    const body = kept.length ? { video: video.value, samples: [...kept, here] } : { video: video.value, ...here };
    try {
      const r = await api.post<{ range: Range; recall: number; negative_rate: number; positives: number; frames: number }>('/api/colour/learn', body);
      if (seq !== learnSent) return;
      range = r.range;
      setSliders(r.range);
      status(msg, `learned from ${r.positives} pixels on ${r.frames} frame${r.frames > 1 ? 's' : ''}: recall ${(100 * r.recall).toFixed(1)} %, ${(100 * r.negative_rate).toFixed(3)} % of other pixels selected`);
    } catch (e) {
      if (seq === learnSent) status(msg, (e as Error).message, true);
    } finally {
      msg.dataset.learned = String(++learnAnswered);
    }
    drawOverlay();
  }

  image.addEventListener('pointerdown', (e) => {
    drag = toImage(e);
    dragNow = null;
    image.setPointerCapture(e.pointerId);
  });
  image.addEventListener('pointermove', (e) => {
    if (!drag) return;
    dragNow = toImage(e);
    drawOverlay();
  });
  image.addEventListener('pointerup', (e) => {
    if (!drag || !img) return;
    if (shownFrame < 0) {  // the frame shown is another video's
      drag = null;
      dragNow = null;
      status(msg, `open a frame of ${video.value} first (Open frame)`, true);
      return;
    }
    const end = toImage(e);
    const start = drag;
    drag = null;
    dragNow = null;
    if (Math.hypot(end[0] - start[0], end[1] - start[1]) < 4) {
      (e.shiftKey ? negatives : points).push([Math.round(start[0] * 10) / 10, Math.round(start[1] * 10) / 10]);
    } else {
      roi = [Math.round(Math.min(start[0], end[0])), Math.round(Math.min(start[1], end[1])),
        Math.round(Math.abs(end[0] - start[0])), Math.round(Math.abs(end[1] - start[1]))];
    }
    void learn();
  });
  clear.onclick = () => {
    kept = [];
    points = [];
    negatives = [];
    roi = null;
    found = [];
    drawOverlay();
  };
  load.onclick = async () => {
    try {
      const next = Number(frame.value);
      img = await api.loadFrame(video.value, next);
      // Another frame: this one's clicks are kept and learned with the next ones; a frame opened
      // again gets its kept clicks back, to add to.
      if (next !== shownFrame) {
        if (points.length || roi) kept.push(clicksHere());
        const back = kept.find((k) => k.frame === next);
        kept = kept.filter((k) => k !== back);
        points = back ? back.points : [];
        negatives = back ? back.negative_points : [];
        roi = back?.roi ?? null;
      }
      shownFrame = next;
      image.width = img.naturalWidth;
      image.height = img.naturalHeight;
      const ctx = image.getContext('2d', { willReadFrequently: true })!;
      ctx.drawImage(img, 0, 0);
      pixels = ctx.getImageData(0, 0, image.width, image.height);
      hsv = new Float32Array(3 * image.width * image.height);
      const d = pixels.data;
      for (let i = 0, n = image.width * image.height; i < n; ++i) hsv.set(hsvOf(d[4 * i], d[4 * i + 1], d[4 * i + 2]), 3 * i);
      found = [];
      status(msg, `frame ${frame.value} of ${video.value}: ${image.width}x${image.height}` + (kept.length ? `; clicks kept on ${kept.length} other frame${kept.length > 1 ? 's' : ''}` : ''));
      drawOverlay();
      image.dataset.ready = '1';
    } catch (e) {
      status(msg, (e as Error).message, true);
    }
  };
  video.addEventListener('change', () => {
    // Clicks are on one video's frames: another video starts afresh (its frame 0 is no frame
    // seen yet, so nothing of this video's is learned on it).
    kept = [];
    points = [];
    negatives = [];
    roi = null;
    found = [];
    shownFrame = -1;
    drawOverlay();
    status(msg, `open a frame of ${video.value} (Open frame): clicks go on its frames`);
  });
  save.onclick = async () => {
    if (!range) return status(msg, 'nothing to save: click on the ball or set the sliders first', true);
    try {
      const r = await api.postSave<{ wrote: string[] }>('/api/colour/save', { range: rangeFromSliders(), out: out.value });
      saved = r.wrote[0];
      savedRange = JSON.stringify(rangeFromSliders());
      status(msg, `wrote ${saved}`);
    } catch (e) {
      status(msg, (e as Error).message, true);
    }
  };
  detect.onclick = async () => {
    try {
      const frames = detectFrames.value.split(/[ ,]+/).filter(Boolean).map(Number);
      // The saved file while the sliders still show what it holds, else the sliders' range.
      const useSaved = saved && savedRange === JSON.stringify(rangeFromSliders()) ? saved : '';
      const body = { video: video.value, frames, ...(useSaved ? { colour: useSaved } : { range: rangeFromSliders() }) };
      const r = await api.post<DetectResult>('/api/colour/detect', body);
      detectResult.replaceChildren(
        el('table', {}, el('tr', {}, ...['frame', 'accepted', 'best u, v px', 'radius px'].map((h) => el('th', { text: h }))),
          ...r.frames.map((f) => {
            const best = f.candidates.find((c) => c.accepted);
            return el('tr', { 'data-frame': String(f.frame), 'data-accepted': String(f.candidates.filter((c) => c.accepted).length), 'data-best': best ? JSON.stringify([best.u, best.v]) : '' },
              el('td', { text: String(f.frame) }), el('td', { text: String(f.candidates.filter((c) => c.accepted).length) }),
              el('td', { text: best ? `${best.u.toFixed(1)}, ${best.v.toFixed(1)}` : '–' }), el('td', { text: best ? best.radius_px.toFixed(1) : '–' }));
          })),
      );
      found = r.frames.find((f) => f.frame === Number(frame.value))?.candidates ?? [];
      drawOverlay();
      status(msg, `detector run on ${frames.length} frame(s) with ${useSaved || 'the slider range'}`);
    } catch (e) {
      status(msg, (e as Error).message, true);
    }
  };
}
