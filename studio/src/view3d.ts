// 3D view: the field, each camera as a frustum at its pose, the ball track (BALL.csv) coloured by
// time, flights (FLIGHTS.json: origin, apex, landing), the rays to the ball at the time of the
// slider from the cameras whose image holds it, and the ball's height over time (uPlot). Live
// mode: the server subscribes to a fusion node's positions (`fuse --publish`) and forwards them
// as 'ball' events.
// Drawing is cheap and on demand: a track is one set of buffers drawn as points and as the line
// segments the markers do not cover, the markers one Points object, the rays one preallocated
// buffer; a frame is rendered only when the view, the time or the data changed (at most once per
// animation frame). On software renderers (SwiftShader, llvmpipe) antialiasing is off (~10x the
// frame time) and at most 0.3 Mpx are drawn, scaled up by the page.
// The benchmark (#bench3d, or the button) renders a 10,000-point track while turning the view and
// reports the displayed frame rate and the render cost per frame, synchronised with the GPU.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import * as api from './api';
import { el, fileSelect, optionsSelect, labelled, status, rampColour } from './ui';

interface BallData {
  samples: number[][]; // frame, time_s, x, y, z, n_cams, err_px
}

interface LandingCall {
  line?: string;
  call?: string;
  in?: boolean;
  margin_m?: number;
}

interface Flight {
  t_start_s: number;
  t_end_s: number;
  origin: number[];
  landing: number[];
  landing_extrapolated?: boolean;
  apex: number[];
  start_event?: string;
  end_event?: string;
  landing_calls?: LandingCall[];
}

export interface BenchResult {
  points: number;
  segments: number; // line segments drawn (those longer than a marker)
  points_drawn: number; // markers drawn in the last frame (software GL: the nearest per pixel)
  paced_fps: number; // frames shown per second while turning (requestAnimationFrame, vsync-bound)
  render_ms_median: number; // render + GPU finish per frame
  render_ms_p95: number;
  renderer: string;
  antialias: boolean;
  canvas: string;
}

// The WebGL renderer's name (unmasked when the browser tells it) and whether it is software.
function probeRenderer(): { name: string; software: boolean } {
  const c = document.createElement('canvas');
  const gl = (c.getContext('webgl2') ?? c.getContext('webgl')) as WebGLRenderingContext | null;
  if (!gl) return { name: 'no WebGL', software: true };
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  const name = String(info ? gl.getParameter(info.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER));
  gl.getExtension('WEBGL_lose_context')?.loseContext();
  return { name, software: /swiftshader|llvmpipe|softpipe|software/i.test(name) };
}

const quantile = (v: number[], q: number) => {
  const s = [...v].sort((a, b) => a - b);
  return s.length ? s[Math.min(s.length - 1, Math.floor(q * s.length))] : NaN;
};

export async function view3dPage(root: HTMLElement, options: { bench?: boolean } = {}): Promise<void> {
  const [list, info] = await Promise.all([api.files(), api.info()]);
  const ball = fileSelect('v3-ball', list, ['csv']);
  const flights = fileSelect('v3-flights', list, ['json'], true);
  const field = optionsSelect('v3-field', info.fields, 'robocup-msl');
  const cameraBoxes = el('div', { id: 'v3-camera-files', class: 'checks' });
  const guess = list.find((f) => f.kind === 'csv' && /ball/i.test(f.path));
  if (guess) ball.value = guess.path;
  // Ticked: the cameras beside the ball file when it has some (cameras of other scenes in the
  // folder would be drawn around this one), else all.
  const folderOf = (p: string) => p.slice(0, p.lastIndexOf('/') + 1);
  const cameraFiles = list.filter((f) => f.kind === 'camera');
  const beside = guess ? cameraFiles.filter((f) => folderOf(f.path) === folderOf(guess.path)) : [];
  for (const f of cameraFiles) {
    const on = !beside.length || beside.includes(f);
    cameraBoxes.append(el('label', {}, el('input', { type: 'checkbox', value: f.path, ...(on ? { checked: '' } : {}) }), f.path));
  }
  const guessFlights = list.find((f) => f.kind === 'json' && /flight/i.test(f.path) && !/truth|synth/i.test(f.path));
  if (guessFlights) flights.value = guessFlights.path;
  const load = el('button', { id: 'v3-load', text: 'Show' });
  const bench = el('button', { id: 'v3-bench', text: 'Benchmark: 10,000-point track' });
  const liveEndpoint = el('input', { id: 'v3-live-endpoint', value: 'tcp://127.0.0.1:5560', size: '22', title: 'the fusion node\'s --publish address' });
  const liveButton = el('button', { id: 'v3-live', text: 'Live' });
  const time = el('input', { id: 'v3-time', type: 'range', min: '0', max: '0', value: '0', step: '1' });
  const timeLabel = el('span', { id: 'v3-time-label' });
  const msg = el('div', { id: 'v3-status', class: 'status' });
  const liveMsg = el('div', { id: 'v3-live-status', class: 'status' });
  const cameraList = el('ul', { id: 'v3-cameras' });
  const flightList = el('ul', { id: 'v3-flight-list' });
  const canvas = el('canvas', { id: 'v3-canvas' });
  const chart = el('div', { id: 'v3-chart' });
  root.replaceChildren(
    el('section', { class: 'controls' }, labelled('Ball track', ball), labelled('Flights', flights), labelled('Field', field), load, bench,
      labelled('Fusion node (fuse --publish)', liveEndpoint), liveButton),
    el('div', { class: 'workspace' },
      el('div', { class: 'main-view' }, canvas, el('div', {}, labelled('Time', el('span', {}, time, timeLabel))), chart, msg, liveMsg),
      el('div', { class: 'side' }, el('h3', { text: 'Camera files' }), cameraBoxes, el('h3', { text: 'Cameras shown' }), cameraList,
        el('h3', { text: 'Flights' }), flightList,
        el('p', { class: 'hint', text: 'Drag to turn, wheel to zoom, right-drag to pan. Track colour: time (blue → red). Flights: origin green, apex white, landing red.' }))),
  );

  const gpu = probeRenderer();
  const antialias = !gpu.software;
  // No preserveDrawingBuffer: it costs a copy of the canvas every frame.
  const renderer = new THREE.WebGLRenderer({ canvas, antialias });
  const width = canvas.parentElement!.clientWidth || 900;
  const height = Math.round(width * 0.55);
  // Software GL fills pixels on the CPU: at most maxSoftwarePixels drawn, scaled up by the page.
  const maxSoftwarePixels = 300000;
  renderer.setPixelRatio(gpu.software ? Math.min(1, Math.sqrt(maxSoftwarePixels / (width * height))) : Math.min(2, window.devicePixelRatio || 1));
  renderer.setSize(width, height);
  canvas.dataset.renderer = gpu.name;
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x1d2630);
  const view = new THREE.PerspectiveCamera(45, width / height, 0.1, 1000);
  view.up.set(0, 0, 1);
  view.position.set(-14, -18, 12);
  const controls = new OrbitControls(view, canvas);

  // Render on demand: at most once per animation frame, only after a change.
  let renders = 0;
  let pending = 0;
  // Tracks culled to the view before each frame (software GL, see trackObject).
  const culled = new Set<(viewProjection: THREE.Matrix4, all: boolean) => void>();
  const viewProjection = new THREE.Matrix4();
  const renderNow = (all = false) => {
    pending = 0;
    if (culled.size) {
      view.updateMatrixWorld();
      viewProjection.multiplyMatrices(view.projectionMatrix, view.matrixWorldInverse);
      for (const cull of culled) cull(viewProjection, all);
    }
    renderer.render(scene, view);
    ++renders;
  };
  const requestRender = () => {
    if (!pending) pending = requestAnimationFrame(() => renderNow());
  };
  controls.addEventListener('change', requestRender);
  // Without preserveDrawingBuffer the canvas reads back blank once shown: a 'render-now' event
  // draws at once, so that a reader in the same task (tests, a capture) gets the picture
  // (detail {all: true}: every marker, none culled; for comparison).
  canvas.addEventListener('render-now', (e) => renderNow(Boolean((e as CustomEvent).detail?.all)));

  let dynamic = new THREE.Group();
  let samples: number[][] = [];
  let cams: api.CameraJson[] = [];
  let plot: uPlot | null = null;

  // The ball marker and the rays to it: built once, moved by writing their buffers.
  const ballMarker = new THREE.Mesh(new THREE.SphereGeometry(0.15, 16, 12), new THREE.MeshBasicMaterial({ color: 0xff8800 }));
  ballMarker.visible = false;
  const maxRays = 64;
  const rayPositions = new Float32Array(maxRays * 2 * 3);
  const rayGeometry = new THREE.BufferGeometry();
  rayGeometry.setAttribute('position', new THREE.BufferAttribute(rayPositions, 3).setUsage(THREE.DynamicDrawUsage));
  rayGeometry.setDrawRange(0, 0);
  const rays = new THREE.LineSegments(rayGeometry, new THREE.LineBasicMaterial({ color: 0xffff88, transparent: true, opacity: 0.6 }));
  rays.frustumCulled = false;
  scene.add(ballMarker, rays);

  // Whether camera c's image holds world point p: in front of it, and its normalized point inside
  // the image's outline through the lens (the server's), else inside the pinhole's frame.
  function holds(c: api.CameraJson, p: number[]): boolean {
    const r = c.cam_from_world_rotation!;
    const t = c.tvec!;
    const z = r[6] * p[0] + r[7] * p[1] + r[8] * p[2] + t[2];
    if (!(z > 0)) return false;
    const x = (r[0] * p[0] + r[1] * p[1] + r[2] * p[2] + t[0]) / z;
    const y = (r[3] * p[0] + r[4] * p[1] + r[5] * p[2] + t[1]) / z;
    const outline = c.image_outline_normalized ?? [];
    if (outline.length < 3) {
      const u = c.fx * x + c.cx;
      const v = c.fy * y + c.cy;
      return u >= -0.5 && u < c.width - 0.5 && v >= -0.5 && v < c.height - 0.5;
    }
    let inside = false;  // even-odd rule
    for (let i = 0, j = outline.length - 1; i < outline.length; j = i++) {
      const [xi, yi] = outline[i];
      const [xj, yj] = outline[j];
      if (yi > y !== yj > y && x < ((xj - xi) * (y - yi)) / (yj - yi) + xi) inside = !inside;
    }
    return inside;
  }

  // Rays from the cameras whose image holds the ball (BALL.csv does not say which cameras found
  // it); returns those cameras.
  function setBall(p: number[] | null): api.CameraJson[] {
    ballMarker.visible = !!p;
    if (!p) {
      rayGeometry.setDrawRange(0, 0);
      return [];
    }
    ballMarker.position.set(p[0], p[1], p[2]);
    const from = cams.filter((c) => holds(c, p)).slice(0, maxRays);
    const n = from.length;
    from.forEach((c, i) => {
      rayPositions.set(c.position_m!, 6 * i);
      rayPositions.set([p[0], p[1], p[2]], 6 * i + 3);
    });
    rayGeometry.setDrawRange(0, 2 * n);
    (rayGeometry.attributes.position as THREE.BufferAttribute).needsUpdate = true;
    rayGeometry.computeBoundingSphere();
    return from;
  }

  function fieldGroup(f: api.FieldModel): THREE.Group {
    const g = new THREE.Group();
    const L = f.length_m + 2 * f.surround_m;
    const W = f.width_m + 2 * f.surround_m;
    const ground = new THREE.Mesh(new THREE.PlaneGeometry(L, W), new THREE.MeshBasicMaterial({ color: f.surface === 'court' ? 0x9a6b45 : 0x2e6b31 }));
    g.add(ground);
    const pts: number[] = [];
    for (const s of f.segments) pts.push(s.a[0], s.a[1], 0.01, s.b[0], s.b[1], 0.01);
    for (const a of f.arcs) {
      const n = Math.max(8, Math.ceil((a.end_rad - a.start_rad) * a.radius_m * 5));
      for (let i = 0; i < n; ++i) {
        const t0 = a.start_rad + ((a.end_rad - a.start_rad) * i) / n;
        const t1 = a.start_rad + ((a.end_rad - a.start_rad) * (i + 1)) / n;
        pts.push(a.centre[0] + a.radius_m * Math.cos(t0), a.centre[1] + a.radius_m * Math.sin(t0), 0.01,
          a.centre[0] + a.radius_m * Math.cos(t1), a.centre[1] + a.radius_m * Math.sin(t1), 0.01);
      }
    }
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.Float32BufferAttribute(pts, 3));
    g.add(new THREE.LineSegments(geo, new THREE.LineBasicMaterial({ color: 0xffffff })));
    return g;
  }

  // World point of a pixel at depth `d` metres in front of the camera.
  function pixelAt(c: api.CameraJson, u: number, v: number, d: number): THREE.Vector3 {
    const r = c.cam_from_world_rotation!;
    const xc = [((u - c.cx) / c.fx) * d, ((v - c.cy) / c.fy) * d, d];
    const p = c.position_m!;
    return new THREE.Vector3(
      p[0] + r[0] * xc[0] + r[3] * xc[1] + r[6] * xc[2],
      p[1] + r[1] * xc[0] + r[4] * xc[1] + r[7] * xc[2],
      p[2] + r[2] * xc[0] + r[5] * xc[1] + r[8] * xc[2]);
  }

  // Every camera's frustum in one LineSegments (vertex colours).
  function frusta(cs: api.CameraJson[], colours: THREE.Color[]): THREE.LineSegments {
    const pos: number[] = [];
    const col: number[] = [];
    cs.forEach((c, ci) => {
      const o = new THREE.Vector3(...(c.position_m as [number, number, number]));
      const k = [[0, 0], [c.width, 0], [c.width, c.height], [0, c.height]].map(([u, v]) => pixelAt(c, u - 0.5, v - 0.5, 1.5));
      for (let i = 0; i < 4; ++i) {
        for (const p of [o, k[i], k[i], k[(i + 1) % 4]]) {
          pos.push(p.x, p.y, p.z);
          col.push(colours[ci].r, colours[ci].g, colours[ci].b);
        }
      }
    });
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    geo.setAttribute('color', new THREE.Float32BufferAttribute(col, 3));
    return new THREE.LineSegments(geo, new THREE.LineBasicMaterial({ vertexColors: true }));
  }

  // Pixel grids shared by the culled tracks (frame stamp, nearest depth, its sample), sized to
  // the drawing buffer; allocated once.
  const bufferSize = renderer.getDrawingBufferSize(new THREE.Vector2());
  const gridW = Math.max(1, Math.round(bufferSize.x));
  const gridH = Math.max(1, Math.round(bufferSize.y));
  const gridStamp = new Uint32Array(gridW * gridH);
  const gridDepth = new Float32Array(gridW * gridH);
  const gridBest = new Int32Array(gridW * gridH);
  let stamp = 0;

  // A track: one set of positions and time colours drawn as points (every sample) and as line
  // segments between consecutive samples. A segment shorter than a marker's width lies under the
  // markers at its ends (same colour) and is left out: dense tracks (a ball rolling or at rest,
  // 100 Hz samples) draw few segments. Software GL pays ~0.5 us per primitive, so there each
  // frame draws, of the markers whose centres fall in the same pixel, only the nearest (the
  // later one on a tie): the others lie under it, shifted by less than a pixel.
  const markerSize = 0.12; // PointsMaterial size; a marker spans markerSize * tan(fov / 2) metres
  function trackObject(s: number[][]): THREE.Group {
    const pos = new Float32Array(3 * s.length);
    const col = new Float32Array(3 * s.length);
    const t0 = s.length ? s[0][1] : 0;
    const span = s.length > 1 ? s[s.length - 1][1] - t0 || 1 : 1;
    s.forEach((row, i) => {
      pos[3 * i] = row[2];
      pos[3 * i + 1] = row[3];
      pos[3 * i + 2] = row[4];
      col.set(rampColour((row[1] - t0) / span), 3 * i);
    });
    const geo = new THREE.BufferGeometry();
    const position = new THREE.BufferAttribute(pos, 3);
    const colour = new THREE.BufferAttribute(col, 3);
    geo.setAttribute('position', position);
    geo.setAttribute('color', colour);
    const covered = markerSize * Math.tan(THREE.MathUtils.degToRad(view.fov / 2));
    const pairs: number[] = [];
    for (let i = 1; i < s.length; ++i) {
      const d = Math.hypot(pos[3 * i] - pos[3 * i - 3], pos[3 * i + 1] - pos[3 * i - 2], pos[3 * i + 2] - pos[3 * i - 1]);
      if (d > covered) pairs.push(i - 1, i);
    }
    const lineGeo = new THREE.BufferGeometry();
    lineGeo.setAttribute('position', position);
    lineGeo.setAttribute('color', colour);
    lineGeo.setIndex(pairs);
    const g = new THREE.Group();
    const points = new THREE.Points(geo, new THREE.PointsMaterial({ size: markerSize, vertexColors: true }));
    g.add(points);
    if (gpu.software && s.length) {
      const n = s.length;
      const index = new THREE.BufferAttribute(new Uint32Array(n), 1).setUsage(THREE.DynamicDrawUsage);
      geo.setIndex(index);
      const cellOf = new Int32Array(n);
      const margin = 16; // px: markers centred this far off the canvas may still show an edge
      const cull = (vp: THREE.Matrix4, all: boolean) => {
        const e = vp.elements;
        if (++stamp === 0xffffffff) {
          gridStamp.fill(0);
          stamp = 1;
        }
        for (let i = 0; i < n; ++i) {
          const x = pos[3 * i];
          const y = pos[3 * i + 1];
          const z = pos[3 * i + 2];
          const w = e[3] * x + e[7] * y + e[11] * z + e[15];
          cellOf[i] = -1;
          if (w <= view.near) continue;
          const px = Math.floor(((e[0] * x + e[4] * y + e[8] * z + e[12]) / w + 1) * 0.5 * gridW);
          const py = Math.floor(((e[1] * x + e[5] * y + e[9] * z + e[13]) / w + 1) * 0.5 * gridH);
          if (px < 0 || py < 0 || px >= gridW || py >= gridH) {
            if (px >= -margin && py >= -margin && px < gridW + margin && py < gridH + margin) cellOf[i] = -2;
            continue;
          }
          const k = py * gridW + px;
          cellOf[i] = k;
          if (gridStamp[k] !== stamp || w <= gridDepth[k]) {
            gridStamp[k] = stamp;
            gridDepth[k] = w;
            gridBest[k] = i;
          }
        }
        const out = index.array as Uint32Array;
        let kept = 0;
        for (let i = 0; i < n; ++i) {
          const k = cellOf[i];
          if (all || k === -2 || (k >= 0 && gridBest[k] === i)) out[kept++] = i;
        }
        index.clearUpdateRanges();
        index.addUpdateRange(0, kept);
        index.needsUpdate = true;
        geo.setDrawRange(0, kept);
        g.userData.drawn = kept;
      };
      culled.add(cull);
      g.userData.cull = cull;
    }
    g.add(new THREE.LineSegments(lineGeo, new THREE.LineBasicMaterial({ vertexColors: true, transparent: true, opacity: 0.5 })));
    g.userData.segments = pairs.length / 2;
    return g;
  }

  // Flight markers (origin, apex, landing) as one Points object.
  function flightMarkers(fl: Flight[]): THREE.Points {
    const pos: number[] = [];
    const col: number[] = [];
    const add = (p: number[], c: number[]) => {
      pos.push(p[0], p[1], p[2]);
      col.push(...c);
    };
    for (const f of fl) {
      add(f.origin, [0.2, 1, 0.4]);
      add(f.apex, [1, 1, 1]);
      add(f.landing, [1, 0.2, 0.2]);
    }
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    geo.setAttribute('color', new THREE.Float32BufferAttribute(col, 3));
    return new THREE.Points(geo, new THREE.PointsMaterial({ size: 0.3, vertexColors: true }));
  }

  function setTime(i: number) {
    if (!samples.length) return;
    const s = samples[Math.min(i, samples.length - 1)];
    const from = setBall([s[2], s[3], s[4]]);
    timeLabel.textContent = ` t = ${s[1].toFixed(3)} s (frame ${s[0]}), ball at (${s[2].toFixed(2)}, ${s[3].toFixed(2)}, ${s[4].toFixed(2)}) m from ${s[5]} cameras; rays from the ${from.length} of ${cams.length} cameras shown whose image holds it`;
    timeLabel.dataset.frame = String(s[0]);
    timeLabel.dataset.rays = JSON.stringify(from.map((c) => c.name));
    plot?.setCursor({ left: plot.valToPos(s[1], 'x'), top: 10 });
    requestRender();
  }

  async function loadCameras(): Promise<void> {
    const checked = [...cameraBoxes.querySelectorAll<HTMLInputElement>('input:checked')].map((b) => b.value);
    // A file that is not a camera is left out (and named) rather than failing the view.
    const cs = await Promise.allSettled(checked.map((p) => api.get<api.CameraJson>('/api/camera', { path: p }).then((c) => ({ ...c, path: p }))));
    cams = cs.flatMap((r) => (r.status === 'fulfilled' && r.value.has_pose ? [r.value] : []));
    const unreadable = checked.filter((_, i) => cs[i].status === 'rejected');
    if (unreadable.length) status(liveMsg, `not camera files: ${unreadable.join(', ')}`, true);
  }

  function rebuildStatic(f: api.FieldModel): void {
    scene.remove(dynamic);
    dynamic.traverse((o) => {
      if (o.userData.cull) culled.delete(o.userData.cull);
      const m = o as THREE.Mesh;
      m.geometry?.dispose();
      (m.material as THREE.Material | undefined)?.dispose();
    });
    dynamic = new THREE.Group();
    dynamic.add(fieldGroup(f));
    cameraList.replaceChildren();
    const colours = cams.map((_, i) => new THREE.Color().setHSL(i / Math.max(1, cams.length), 0.8, 0.6));
    if (cams.length) dynamic.add(frusta(cams, colours));
    cams.forEach((c, i) => {
      const p = c.position_m!.map((v) => v.toFixed(2)).join(', ');
      cameraList.append(el('li', { style: `color:#${colours[i].getHexString()}`, text: `${c.name || (c as { path?: string }).path} at (${p}) m, ${c.width}x${c.height}` }));
    });
    scene.add(dynamic);
  }

  async function show() {
    try {
      status(msg, 'loading…');
      const [f, b, fl] = await Promise.all([
        api.get<api.FieldModel>('/api/field', { name: field.value }),
        api.get<BallData>('/api/ball', { path: ball.value }),
        flights.value ? api.get<Flight[]>('/api/json', { path: flights.value }) : Promise.resolve([] as Flight[]),
        loadCameras(),
      ]);
      dropBenchTrack();
      rebuildStatic(f);
      samples = b.samples;
      dynamic.add(trackObject(samples));
      flightList.replaceChildren();
      const fa = Array.isArray(fl) ? fl.filter((x) => x.origin && x.apex && x.landing) : [];
      if (fa.length) dynamic.add(flightMarkers(fa));
      fa.forEach((x, i) => {
        const calls = (x.landing_calls ?? []).map((c) => c.call ?? (c.in === undefined ? '' : c.in ? 'in' : 'out')).filter(Boolean);
        flightList.append(el('li', {
          text: `${i + 1}: ${x.t_start_s.toFixed(2)}–${x.t_end_s.toFixed(2)} s${x.start_event ? ` (${x.start_event} → ${x.end_event})` : ''}, apex ${x.apex[2].toFixed(2)} m, ${x.landing_extrapolated ? 'would land (extrapolated past the last sample) at' : 'lands at'} (${x.landing[0].toFixed(2)}, ${x.landing[1].toFixed(2)}) m${calls.length ? ', ' + calls.join(', ') : ''}`,
        }));
      });
      time.max = String(Math.max(0, samples.length - 1));
      time.value = '0';
      drawChart(fa);
      setTime(0);
      status(msg, `${samples.length} ball positions, ${cams.length} cameras, ${fa.length} flights`);
      renderNow();
      canvas.dataset.ready = '1';
    } catch (e) {
      status(msg, (e as Error).message, true);
    }
  }

  function drawChart(fl: Flight[]) {
    plot?.destroy();
    const t = samples.map((s) => s[1]);
    const z = samples.map((s) => s[4]);
    plot = new uPlot({
      width: canvas.clientWidth || width, height: 170,
      series: [{ label: 't (s)' }, { label: 'ball height z (m)', stroke: '#f80', width: 1.5, points: { show: false } }],
      axes: [{ label: 'time (s)', stroke: '#ccc' }, { label: 'z (m)', stroke: '#ccc' }],
      scales: { x: { time: false } },
      hooks: {
        draw: [(u: uPlot) => {
          const ctx = u.ctx;
          ctx.fillStyle = 'rgba(80, 160, 255, 0.15)';
          for (const f of fl) {
            const x0 = u.valToPos(f.t_start_s, 'x', true);
            const x1 = u.valToPos(f.t_end_s, 'x', true);
            ctx.fillRect(x0, u.bbox.top, x1 - x0, u.bbox.height);
          }
        }],
      },
    }, [t, z], chart);
  }

  // ---- benchmark: a 10,000-point track over the field (and the cameras shown); it stays shown
  // until the next benchmark or Show. The page's ?points=N sets the track's length and
  // ?scene=empty leaves the field and cameras out (the baseline: what drawing nothing reaches).
  const benchQuery = new URLSearchParams(location.search);
  const benchPoints = Math.max(0, Math.min(1e6, Number(benchQuery.get('points') ?? 10000) || 0));
  const benchEmpty = benchQuery.get('scene') === 'empty';
  let benchTrack: THREE.Group | null = null;
  function dropBenchTrack() {
    if (!benchTrack) return;
    scene.remove(benchTrack);
    culled.delete(benchTrack.userData.cull);
    for (const c of benchTrack.children) (c as THREE.Points).geometry.dispose();
    benchTrack = null;
  }
  async function runBench(): Promise<BenchResult> {
    const n = benchPoints;
    const s: number[][] = [];
    for (let i = 0; i < n; ++i) {
      const t = i / 100;
      s.push([i, t, 8 * Math.cos(t / 7), 5 * Math.sin(t / 5), Math.abs(3 * Math.sin(t)), 2, 0.5]);
    }
    if (!dynamic.children.length && !benchEmpty) {
      await loadCameras();
      rebuildStatic(await api.get<api.FieldModel>('/api/field', { name: field.value }));
    }
    dropBenchTrack();
    const track = trackObject(s);
    if (n) scene.add(track);
    const axis = new THREE.Vector3(0, 0, 1);
    const turn = () => {
      view.position.applyAxisAngle(axis, 0.01);
      controls.update();
    };
    // Render cost: each frame rendered and waited for (a 1-pixel read finishes the GPU's work).
    const gl = renderer.getContext();
    const pixel = new Uint8Array(4);
    const costs: number[] = [];
    for (let i = 0; i < 30; ++i) {
      const t0 = performance.now();
      turn();
      renderNow();
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
      if (i >= 5) costs.push(performance.now() - t0);
      if (i % 10 === 9) await new Promise((r) => setTimeout(r, 0));
    }
    // Frames shown: the view turns every animation frame for 2 s, rendered on demand.
    const first = renders;
    const start = performance.now();
    await new Promise<void>((done) => {
      const step = () => {
        turn();
        if (performance.now() - start < 2000) requestAnimationFrame(step);
        else done();
      };
      requestAnimationFrame(step);
    });
    const paced = ((renders - first) * 1000) / (performance.now() - start);
    benchTrack = track;
    return {
      points: n,
      segments: n ? track.userData.segments : 0,
      points_drawn: n ? track.userData.drawn ?? n : 0,
      paced_fps: Number(paced.toFixed(1)),
      render_ms_median: Number(quantile(costs, 0.5).toFixed(2)),
      render_ms_p95: Number(quantile(costs, 0.95).toFixed(2)),
      renderer: gpu.name,
      antialias,
      canvas: `${canvas.width}x${canvas.height}`,
    };
  }

  // ---- live: positions from the fusion node through the server ('ball' events).
  const liveCapacity = 10000;
  const livePositions = new Float32Array(3 * liveCapacity);
  const liveColours = new Float32Array(3 * liveCapacity);
  const liveGeometry = new THREE.BufferGeometry();
  liveGeometry.setAttribute('position', new THREE.BufferAttribute(livePositions, 3).setUsage(THREE.DynamicDrawUsage));
  liveGeometry.setAttribute('color', new THREE.BufferAttribute(liveColours, 3).setUsage(THREE.DynamicDrawUsage));
  liveGeometry.setDrawRange(0, 0);
  const liveTrack = new THREE.Points(liveGeometry, new THREE.PointsMaterial({ size: 0.12, vertexColors: true }));
  liveTrack.frustumCulled = false;
  let liveCount = 0;
  let liveOn = false;
  const onEvent = (e: Event) => {
    const { type, data } = (e as CustomEvent).detail as { type: string; data: Record<string, number | string> };
    if (type === 'live') {
      liveOn = data.state === 'running';
      liveButton.textContent = liveOn ? 'Stop live' : 'Live';
      status(liveMsg, `live: ${data.state} ${data.endpoint ?? ''} ${data.error ?? ''}`.trim(), data.state === 'failed');
      return;
    }
    if (type !== 'ball' || !liveOn) return;
    const p = [Number(data.x_m), Number(data.y_m), Number(data.z_m)];
    const k = liveCount % liveCapacity;
    livePositions.set(p, 3 * k);
    liveColours.set(rampColour(((Number(data.time_s) % 10) + 10) % 10 / 10), 3 * k);
    ++liveCount;
    liveGeometry.setDrawRange(0, Math.min(liveCount, liveCapacity));
    (liveGeometry.attributes.position as THREE.BufferAttribute).needsUpdate = true;
    (liveGeometry.attributes.color as THREE.BufferAttribute).needsUpdate = true;
    setBall(p);
    liveMsg.dataset.count = String(liveCount);
    status(liveMsg, `live: ${liveCount} positions, frame ${data.frame}, ball at (${p.map((v) => v.toFixed(2)).join(', ')}) m, ${data.n_cams} cameras, latency ${(1000 * Number(data.latency_s)).toFixed(0)} ms`);
    requestRender();
  };
  window.addEventListener('studio-event', onEvent);
  const observer = new MutationObserver(() => {
    if (!canvas.isConnected) {
      window.removeEventListener('studio-event', onEvent);
      observer.disconnect();
      renderer.dispose();
    }
  });
  observer.observe(root, { childList: true });

  liveButton.onclick = async () => {
    try {
      if (liveOn) {
        await api.post('/api/live/stop', {});
        return;
      }
      if (!dynamic.children.length) {
        await loadCameras();
        rebuildStatic(await api.get<api.FieldModel>('/api/field', { name: field.value }));
      }
      liveCount = 0;
      liveGeometry.setDrawRange(0, 0);
      if (!liveTrack.parent) scene.add(liveTrack);
      const r = await api.post<{ state: string; endpoint: string }>('/api/live/start', { endpoint: liveEndpoint.value });
      liveOn = r.state === 'running';
      liveButton.textContent = liveOn ? 'Stop live' : 'Live';
      status(liveMsg, `live: waiting for positions from ${r.endpoint}`);
      requestRender();
    } catch (e) {
      status(liveMsg, (e as Error).message, true);
    }
  };

  // A feed the server already runs (`studio --live`, or another page): show it.
  void api.get<{ state: string; endpoint: string }>('/api/live').then((st) => {
    if (st.state !== 'running' || !canvas.isConnected) return;
    liveOn = true;
    liveEndpoint.value = st.endpoint;
    liveButton.textContent = 'Stop live';
    if (!liveTrack.parent) scene.add(liveTrack);
    status(liveMsg, `live: waiting for positions from ${st.endpoint}`);
  }).catch(() => {});

  time.addEventListener('input', () => setTime(Number(time.value)));
  load.onclick = () => void show();
  bench.onclick = async () => {
    status(msg, 'benchmark running…');
    const r = await runBench();
    status(msg, `benchmark: ${r.points} points (${r.points_drawn} drawn in the last frame, the others under them; ${r.segments} line segments longer than a marker), ${r.paced_fps} frames/s shown while turning; render ${r.render_ms_median} ms per frame (p95 ${r.render_ms_p95} ms) → ${(1000 / r.render_ms_median).toFixed(0)} frames/s possible; canvas ${r.canvas}; ${r.renderer}${r.antialias ? '' : ', no antialiasing'}`);
    msg.dataset.fps = String(r.paced_fps);
    msg.dataset.bench = JSON.stringify(r);
  };
  renderNow();
  if (options.bench) {
    bench.click();
  } else if (ball.value) {
    await show();
  }
}
