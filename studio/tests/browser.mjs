// Browser tests of the studio: playwright-core drives Debian's chromium (never a downloaded
// browser) against `fieldvision studio` serving a synthetic scene (tests/run.sh sets it up).
//   calibrate: click the field keypoints at their true pixels -> saved pose within 2 cm of truth;
//     six clicks 3 px off, refined against the painted lines -> within 2 cm; intrinsics from
//     OpenCV's chessboard samples -> fx within 1 % of OpenCV's, per-view errors listed
//   ball colour: click on the ball -> saved colour file; the detector (API and CLI) finds the ball
//   3D view: a ball result renders (canvas not blank, every camera listed); 10,000-point benchmark
//     (frames/s reported, not asserted)
//   live: positions of `fuse --publish` (four `node`s on the scene) reach the 3D view
//   zones: a polygon clicked on the field map is saved
//   jobs: a job runs to the end, another is cancelled (states from the server's events)
//   players: the tactical board plays with the zones, the video beside it, heat maps, speed chart,
//     zone alerts on a timeline and the stats table (as /api/players/stats); export (CSV, PNG)
// Usage: node browser.mjs URL OUT_DIR FIELDVISION
import { launchChromium } from './chromium.mjs';
import { execFileSync, spawn } from 'node:child_process';
import net from 'node:net';
import fs from 'node:fs';
import path from 'node:path';

const [url, out, fv] = process.argv.slice(2);
const work = path.join(out, 'work');
const failures = [];
let lapStart = Date.now();
function lap(what) {
  console.log(`  (${what}: ${((Date.now() - lapStart) / 1000).toFixed(1)} s)`);
  lapStart = Date.now();
}
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures.push(what);
}
async function api(p, body) {
  const res = await fetch(new URL(p, url), body ? { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body) } : {});
  if (!res.ok) throw new Error(`${p}: ${res.status} ${await res.text()}`);
  return res.json();
}
function readCsv(file) {
  const [head, ...rows] = fs.readFileSync(file, 'utf8').trim().split('\n');
  const cols = head.split(',');
  return rows.map((r) => Object.fromEntries(r.split(',').map((v, i) => [cols[i], v])));
}

// A free loopback port (bound, read, released).
function freePort() {
  return new Promise((resolve, reject) => {
    const srv = net.createServer();
    srv.on('error', reject);
    srv.listen(0, '127.0.0.1', () => {
      const { port } = srv.address();
      srv.close(() => resolve(port));
    });
  });
}
const children = [];
function start(args, log) {
  const child = spawn(fv, args, { cwd: work, stdio: ['ignore', fs.openSync(path.join(out, log), 'w'), 'pipe'] });
  child.stderr.on('data', (d) => fs.appendFileSync(path.join(out, log), d));
  children.push(child);
  return child;
}

const browser = await launchChromium('fv-studio-chromium-');
const page = browser.page;
const consoleErrors = [];
page.on('pageerror', (e) => consoleErrors.push(String(e)));
page.on('console', (m) => m.type() === 'error' && !/Failed to load resource/.test(m.text()) && consoleErrors.push(m.text()));
// Replies with 4xx/5xx that the pages did not ask for on purpose.
// (A pose request with too few or collinear points is answered 422 and shown on the page; a job
// whose output exists, or an export into a folder that is not empty, 409, in the checks below.)
const asked = (r) => (r.status() === 422 && r.url().includes('/api/calibrate/pose')) ||
  (r.status() === 409 && (r.url().endsWith('/api/jobs') || r.url().endsWith('/api/players/export')));
page.on('response', (r) => r.status() >= 400 && !asked(r) && consoleErrors.push(`${r.status()} ${r.url()}`));
page.setDefaultTimeout(20000);

// Clicks image pixel (u, v) (OpenCV convention) on a canvas showing the image scaled.
async function clickPixel(canvas, u, v) {
  const box = await canvas.boundingBox();
  const size = await canvas.evaluate((c) => [c.width, c.height]);
  const x = box.x + ((u + 0.5) * box.width) / size[0];
  const y = box.y + ((v + 0.5) * box.height) / size[1];
  await page.mouse.move(x, y);
  await page.mouse.down();
  await page.mouse.up();
}

try {
  // ---- first load of the app (the browser itself warmed up on a blank page first)
  await page.goto('about:blank');
  const t0 = Date.now();
  await page.goto(url + '#calibrate', { waitUntil: 'load' });
  const loadMs = await page.evaluate(() => performance.getEntriesByType('navigation')[0].loadEventEnd);
  await page.waitForSelector('#page[data-ready="1"]');
  console.log(`first page load: ${loadMs.toFixed(0)} ms to the load event (navigation timing), page ready after ${Date.now() - t0} ms`);
  const resources = await page.evaluate(() => performance.getEntriesByType('resource').map((e) => `${e.name.replace(/^.*\//, '')} ${e.startTime.toFixed(0)}+${e.duration.toFixed(0)} ms`));
  console.log(`  resources: ${resources.join(', ')}`);
  check(loadMs < 1000, `first page load under 1 s on loopback (${loadMs.toFixed(0)} ms)`);

  // ---- calibrate
  await page.selectOption('#cal-video', 'scene/cam1.avi');
  await page.selectOption('#cal-camera', 'scene/cam1.yaml');
  await page.fill('#cal-out', 'scene/cam1_studio.yaml');
  await page.click('#cal-load');
  await page.waitForSelector('#cal-image[data-ready="1"]');
  const truthCam = await api('/api/camera?path=scene/cam1.yaml');
  const projected = await api('/api/calibrate/project', { camera: 'scene/cam1.yaml', field: 'robocup-msl' });
  const canvas = page.locator('#cal-image');
  const kps = projected.keypoints_px.filter((k) => k.u > 5 && k.v > 5 && k.u < truthCam.width - 5 && k.v < truthCam.height - 5);
  check(kps.length >= 6, `cam1 sees ${kps.length} field keypoints`);
  for (const k of kps) {
    await page.click(`[data-keypoint="${k.name}"]`);
    await clickPixel(canvas, k.u, k.v);
  }
  await page.waitForFunction((n) => document.querySelectorAll('#cal-points tr').length === n + 1, kps.length);
  await page.click('#cal-save');
  await page.waitForFunction(() => /wrote/.test(document.querySelector('#cal-status').textContent));
  await page.screenshot({ path: path.join(out, 'calibrate.jpg'), quality: 70 });
  const saved = await api('/api/camera?path=scene/cam1_studio.yaml');
  const d = Math.hypot(...saved.position_m.map((v, i) => v - truthCam.position_m[i]));
  console.log(`calibrate: ${kps.length} keypoints clicked; camera position error ${(100 * d).toFixed(2)} cm (${(await page.textContent('#cal-rms'))})`);
  check(d < 0.02, `pose from clicks within 2 cm of the truth (${(100 * d).toFixed(2)} cm)`);

  // Six clicks off by 3 px: a pose some centimetres off, which the painted lines pull back.
  await page.click('#cal-load');
  await page.waitForFunction(() => document.querySelectorAll('#cal-points tr').length === 0);
  const few = kps.slice(0, 6);
  for (const [i, k] of few.entries()) {
    await page.click(`[data-keypoint="${k.name}"]`);
    await clickPixel(canvas, k.u + (i % 2 ? 3 : -3), k.v + (Math.floor(i / 2) % 2 ? 3 : -3));
  }
  await page.waitForFunction(() => document.querySelectorAll('#cal-points tr').length === 7);
  const clickedAt = JSON.parse(await page.getAttribute('#cal-position', 'data-position'));
  const dClicks = Math.hypot(...clickedAt.map((v, i) => v - truthCam.position_m[i]));
  await page.click('#cal-refine');
  await page.waitForSelector('#cal-refine-summary');
  const refined = await page.evaluate(() => ({ ...document.querySelector('#cal-refine-summary').dataset }));
  check(refined.accepted === '1' && Number(refined.afterMm) < Number(refined.beforeMm),
    `refined against the painted lines: line error ${Number(refined.beforeMm).toFixed(1)} -> ${Number(refined.afterMm).toFixed(1)} mm`);
  await page.fill('#cal-out', 'scene/cam1_refined.yaml');
  await page.click('#cal-save');
  await page.waitForFunction(() => /wrote .*refined/.test(document.querySelector('#cal-status').textContent));
  await page.screenshot({ path: path.join(out, 'calibrate_refine.jpg'), quality: 70 });
  const savedRefined = await api('/api/camera?path=scene/cam1_refined.yaml');
  const dRefined = Math.hypot(...savedRefined.position_m.map((v, i) => v - truthCam.position_m[i]));
  console.log(`refine: 6 clicks 3 px off put the camera ${(100 * dClicks).toFixed(1)} cm off; refined against the lines ${(100 * dRefined).toFixed(2)} cm`);
  check(dRefined < 0.02 && dRefined < dClicks, `refined pose within 2 cm of the truth (${(100 * dRefined).toFixed(2)} cm; clicks alone ${(100 * dClicks).toFixed(1)} cm)`);

  // Intrinsics from OpenCV's chessboard samples (when ../shared/data is there).
  if (process.env.FV_BOARDS_REFERENCE && fs.existsSync(path.join(work, 'boards'))) {
    // OpenCV's own calibration of these views (left_intrinsics.yml, camera_matrix data[0]).
    const reference = Number(fs.readFileSync(process.env.FV_BOARDS_REFERENCE, 'utf8').match(/camera_matrix:[^[]*\[\s*([-0-9.e+]+)/)[1]);
    await page.fill('#int-images', 'boards/left*.jpg');
    await page.fill('#int-out', 'boards/left.yaml');
    await page.click('#int-run');
    await page.waitForFunction(() => /RMS|error|cannot/i.test(document.querySelector('#int-status').textContent), null, { timeout: 60000 });
    const fx = Number(await page.getAttribute('#int-status', 'data-fx'));
    const views = await page.locator('#int-views tr[data-view]').count();
    const worst = Math.max(...(await page.$$eval('#int-views tr[data-view]', (rows) => rows.map((r) => Number(r.dataset.rms)))));
    console.log(`intrinsics: ${await page.textContent('#int-status')}`);
    await page.locator('#int-section').scrollIntoViewIfNeeded();
    await page.screenshot({ path: path.join(out, 'calibrate_intrinsics.jpg'), quality: 70 });
    check(Math.abs(fx - reference) < 0.01 * reference && views === 13 && worst < 1,
      `intrinsics from 13 board images: fx ${fx.toFixed(1)} px (OpenCV ${reference.toFixed(1)}), ${views} views listed, worst view ${worst.toFixed(3)} px`);
  } else {
    console.log('intrinsics: skipped (no ../shared/data/opencv-chessboard)');
  }

  lap('calibrate');
  // ---- ball colour
  await page.goto(url + '#colour');
  await page.waitForSelector('#page[data-ready="1"]');
  await page.selectOption('#col-video', 'scene/cam1.avi');
  const truth2d = readCsv(path.join(work, 'scene/truth_2d.csv')).filter((r) => r.cam === 'cam1');
  const f0 = truth2d.find((r) => Number(r.visible_fraction) > 0.9 && Number(r.radius_px) > 4);
  check(!!f0, 'the ball is visible in a frame of cam1');
  await page.fill('#col-frame', f0.frame);
  await page.click('#col-load');
  await page.waitForSelector('#col-image[data-ready="1"]');
  const [bu, bv, br] = [Number(f0.u_px), Number(f0.v_px), Number(f0.radius_px)];
  const colourCanvas = page.locator('#col-image');
  let clicks = 0;
  for (const [du, dv] of [[0, 0], [0.5, 0], [-0.5, 0], [0, 0.5], [0, -0.5]]) {
    await clickPixel(colourCanvas, bu + du * br, bv + dv * br);
    ++clicks;
    // This click's answer, not an earlier one's (a late answer would overwrite what follows).
    await page.waitForFunction((n) => Number(document.querySelector('#col-status').dataset.learned) >= n, clicks);
  }
  check(/learned/.test(await page.textContent('#col-status')), 'colour learned from the clicks');
  // Another frame's clicks are learned together with these.
  const f1 = truth2d.find((r) => Number(r.visible_fraction) > 0.9 && Number(r.radius_px) > 4 && Math.abs(Number(r.frame) - Number(f0.frame)) >= 5);
  check(!!f1, 'the ball is visible in a second frame of cam1');
  if (f1) {
    await page.fill('#col-frame', f1.frame);
    await page.click('#col-load');
    await page.waitForFunction((f) => document.querySelector('#col-status').textContent.startsWith(`frame ${f} `), f1.frame);
    await clickPixel(colourCanvas, Number(f1.u_px), Number(f1.v_px));
    ++clicks;
    await page.waitForFunction((n) => Number(document.querySelector('#col-status').dataset.learned) >= n, clicks);
    const learned2 = await page.textContent('#col-status');
    check(/on 2 frames/.test(learned2), `colour learned from clicks on two frames (${learned2})`);
  }
  const selected = Number(await page.getAttribute('#col-count', 'data-selected'));
  check(selected > 0 && selected < 20 * Math.PI * br * br, `selected pixels shown (${selected} px; ball disc ${(Math.PI * br * br).toFixed(0)} px)`);
  await page.fill('#col-out', 'ball_colour.json');
  await page.click('#col-save');
  await page.waitForFunction(() => /wrote/.test(document.querySelector('#col-status').textContent));
  const frames = truth2d.filter((r) => Number(r.visible_fraction) > 0.9 && Number(r.radius_px) > 3).filter((_, i) => i % 8 === 0).slice(0, 4);
  await page.fill('#col-detect-frames', frames.map((r) => r.frame).join(','));
  await page.click('#col-detect');
  await page.waitForSelector('#col-detect-result tr[data-frame]');
  await page.screenshot({ path: path.join(out, 'colour.jpg'), quality: 70 });
  for (const r of frames) {
    const best = await page.getAttribute(`#col-detect-result tr[data-frame="${r.frame}"]`, 'data-best');
    const e = best ? Math.hypot(JSON.parse(best)[0] - r.u_px, JSON.parse(best)[1] - r.v_px) : Infinity;
    check(e < 2, `studio detect with the saved colour finds the ball in frame ${r.frame} (${e.toFixed(2)} px off)`);
  }
  // The saved file works with the command-line detector too.
  execFileSync(fv, ['detect', '--camera', 'scene/cam1.yaml', '--video', 'scene/cam1.avi', '--color', 'ball_colour.json',
    '--out', 'det.csv', '--no-progress'], { cwd: work, stdio: 'pipe' });
  const det = readCsv(path.join(work, 'det.csv')).filter((r) => r.accepted === '1' || r.accepted === 'true');
  const hits = truth2d.filter((t) => Number(t.visible_fraction) > 0.9 && Number(t.radius_px) > 3)
    .filter((t) => det.some((r) => r.frame === t.frame && Math.hypot(r.u - t.u_px, r.v - t.v_px) < 2));
  const visible = truth2d.filter((t) => Number(t.visible_fraction) > 0.9 && Number(t.radius_px) > 3).length;
  check(hits.length >= 0.9 * visible, `fieldvision detect --color ball_colour.json finds the ball in ${hits.length}/${visible} frames`);

  lap('ball colour');
  // ---- 3D view
  // Two cameras with cam1's lens that do not hold the ball: 10 m above the field's centre looking
  // up (the ball behind it), and 10 m up 100 m beside the field looking down (the ball in front
  // of it, 10 image widths off its image). No ray from either.
  const cam1Yaml = fs.readFileSync(path.join(work, 'scene/cam1.yaml'), 'utf8');
  const matrix = (key, values) => (text) => text.replace(new RegExp(`(${key}: !!opencv-matrix[\\s\\S]*?data: )\\[[^\\]]*\\]`), `$1[ ${values.join(', ')} ]`);
  const posed = (name, rvec, tvec, position) => [matrix('rvec', rvec), matrix('tvec', tvec), matrix('camera_position_m', position)]
    .reduce((text, f) => f(text), cam1Yaml.replace(/^name: .*$/m, `name: ${name}`));
  fs.mkdirSync(path.join(work, 'extra'), { recursive: true });  // not beside ball.csv: all cameras ticked
  fs.writeFileSync(path.join(work, 'extra/away.yaml'), posed('away', [0, 0, 0], [0, 0, -10], [0, 0, 10]));
  fs.writeFileSync(path.join(work, 'extra/aside.yaml'), posed('aside', [Math.PI, 0, 0], [-100, 0, 10], [100, 0, 10]));
  await page.goto(url + '#view3d');
  await page.waitForSelector('#page[data-ready="1"]');
  await page.selectOption('#v3-ball', 'ball.csv');
  await page.selectOption('#v3-flights', 'flights.json');
  await page.click('#v3-load');
  await page.waitForSelector('#v3-canvas[data-ready="1"]');
  const files = await api('/api/files');
  const withPose = await Promise.all(files.filter((f) => f.kind === 'camera').map((f) => api(`/api/camera?path=${encodeURIComponent(f.path)}`)));
  const nCams = withPose.filter((c) => c.has_pose).length;
  const listed = await page.locator('#v3-cameras li').count();
  check(listed === nCams && nCams >= 4, `3D view lists ${listed} cameras (${nCams} camera files with a pose)`);
  const stats = await page.evaluate(() => {
    const c = document.querySelector('#v3-canvas');
    c.dispatchEvent(new Event('render-now'));
    const t = document.createElement('canvas');
    t.width = c.width;
    t.height = c.height;
    const ctx = t.getContext('2d');
    ctx.drawImage(c, 0, 0);
    const d = ctx.getImageData(0, 0, t.width, t.height).data;
    const colours = new Set();
    let changed = 0;
    for (let i = 0; i < d.length; i += 4) {
      colours.add((d[i] << 16) | (d[i + 1] << 8) | d[i + 2]);
      if (Math.abs(d[i] - 0x1d) + Math.abs(d[i + 1] - 0x26) + Math.abs(d[i + 2] - 0x30) > 30) ++changed;
    }
    return { colours: colours.size, changed: changed / (d.length / 4) };
  });
  check(stats.changed > 0.05 && stats.colours > 20, `3D canvas rendered (${(100 * stats.changed).toFixed(1)} % of pixels off the background, ${stats.colours} colours)`);
  await page.locator('#v3-time').fill('20');
  // Rays from the cameras whose image holds the ball: of the scene's cameras (by name; the
  // camera files made earlier in this test are poses of them, and one of a phone), those that hold
  // the true ball in that frame.
  const shownFrame = await page.locator('#v3-time-label').getAttribute('data-frame');
  const rayNames = JSON.parse((await page.locator('#v3-time-label').getAttribute('data-rays')) ?? '[]');
  const truthNow = readCsv(path.join(work, 'scene/truth_2d.csv')).filter((t) => t.frame === shownFrame);
  const judged = withPose.filter((c) => c.has_pose && truthNow.some((t) => t.cam === c.name));
  const wrong = judged.filter((c) => {
    const t = truthNow.find((r) => r.cam === c.name);
    const inImage = t.u_px >= -0.5 && t.u_px < c.width - 0.5 && t.v_px >= -0.5 && t.v_px < c.height - 0.5;
    return inImage !== rayNames.includes(c.name);
  });
  const apart = ['away', 'aside'].filter((n) => withPose.some((c) => c.name === n) && !rayNames.includes(n));
  check(shownFrame !== null && judged.length >= 4 && wrong.length === 0 && apart.length === 2, `3D view at frame ${shownFrame}: rays from ${rayNames.join(' ')}; of ${judged.length} scene cameras ${wrong.length} drawn against the truth; listed without a ray: ${apart.join(', ')} (away, aside)`);
  await page.screenshot({ path: path.join(out, 'view3d.jpg'), quality: 70 });
  lap('3D view');
  // The benchmark page: a 10,000-point track over the field and the cameras, turned for 2 s.
  // Reported, not asserted: headless chromium renders with SwiftShader (software) on the CI's CPUs.
  await page.goto(url + '#bench3d');
  await page.waitForSelector('#v3-status[data-fps]', { timeout: 60000 });
  const bench = JSON.parse(await page.getAttribute('#v3-status', 'data-bench'));
  console.log(`3D benchmark: ${bench.points} points: ${bench.paced_fps} frames/s shown while turning; render + GPU finish ` +
    `${bench.render_ms_median} ms per frame (p95 ${bench.render_ms_p95} ms, ${(1000 / bench.render_ms_median).toFixed(0)} frames/s possible); ` +
    `${bench.renderer}${bench.antialias ? '' : ', no antialiasing'}`);
  check(bench.paced_fps > 0 && bench.render_ms_median > 0, '3D benchmark measured');
  await page.screenshot({ path: path.join(out, 'bench3d.jpg'), quality: 70 });
  // Software GL draws only the nearest marker per pixel: the picture is that of every marker.
  const culling = await page.evaluate(() => {
    const c = document.querySelector('#v3-canvas');
    const grab = (all) => {
      c.dispatchEvent(new CustomEvent('render-now', { detail: { all } }));
      const t = document.createElement('canvas');
      t.width = c.width;
      t.height = c.height;
      const ctx = t.getContext('2d');
      ctx.drawImage(c, 0, 0);
      return ctx.getImageData(0, 0, t.width, t.height).data;
    };
    const every = grab(true);
    const culled = grab(false);
    let differ = 0;
    for (let i = 0; i < every.length; i += 4) {
      if (Math.abs(every[i] - culled[i]) + Math.abs(every[i + 1] - culled[i + 1]) + Math.abs(every[i + 2] - culled[i + 2]) > 30) ++differ;
    }
    return { differ, pixels: every.length / 4 };
  });
  console.log(`3D benchmark: ${bench.points_drawn} of ${bench.points} markers drawn (nearest per pixel); ${culling.differ} of ` +
    `${culling.pixels} pixels differ from drawing every marker`);
  check(culling.differ < 0.01 * culling.pixels, `culled markers leave the picture as it was (${(100 * culling.differ / culling.pixels).toFixed(2)} % of pixels differ)`);
  // The same turn with nothing drawn: what headless chromium itself shows on this machine.
  await page.goto(new URL('?scene=empty&points=0#bench3d', url).toString());
  await page.waitForSelector('#v3-status[data-fps]', { timeout: 60000 });
  const empty = JSON.parse(await page.getAttribute('#v3-status', 'data-bench'));
  console.log(`3D benchmark baseline, empty scene: ${empty.paced_fps} frames/s shown, render ${empty.render_ms_median} ms; ` +
    `the 10,000-point track reaches ${(100 * bench.paced_fps / empty.paced_fps).toFixed(0)} % of it`);

  lap('3D benchmark');
  // ---- live: the 3D view subscribes (through the server) to a fusion node fed by four camera
  // nodes playing the scene's videos; positions arrive as server events while they are fused.
  await page.goto(url + '#view3d');
  await page.waitForSelector('#v3-canvas[data-ready="1"]');
  const [listenPort, publishPort] = [await freePort(), await freePort()];
  await page.fill('#v3-live-endpoint', `tcp://127.0.0.1:${publishPort}`);
  await page.click('#v3-live');
  await page.waitForFunction(() => /waiting|running/.test(document.querySelector('#v3-live-status').textContent));
  const cameraArgs = [1, 2, 3, 4].flatMap((c) => ['--camera', `scene/cam${c}.yaml`]);
  // The nodes play their videos as cameras triggered together (--realtime --start-at: frame k at
  // the same moment on every node, 3 s from now), so a node that starts late on a loaded machine
  // still delivers its frames in time (sent as fast as read, one node's 40 frames came after the
  // others' had been fused); --ground places the ball from one camera too, and every fused frame
  // with a ball is published.
  const startAt = (Date.now() / 1000 + 3).toFixed(3);
  const fuse = start(['fuse', '--listen', `tcp://127.0.0.1:${listenPort}`, ...cameraArgs, '--out', 'live_ball.csv',
    '--publish', `tcp://127.0.0.1:${publishPort}`, '--idle-exit', '1', '--max-wait', '10', '--ground', '--no-progress'], 'live_fuse.log');
  const fuseEnded = new Promise((resolve) => fuse.on('exit', resolve));
  for (const c of [1, 2, 3, 4]) {
    start(['node', '--camera', `scene/cam${c}.yaml`, '--video', `scene/cam${c}.avi`, '--connect', `tcp://127.0.0.1:${listenPort}`,
      '--realtime', '--start-at', startAt, '--no-progress'], `live_node${c}.log`);
  }
  await Promise.race([fuseEnded, new Promise((r) => setTimeout(r, 60000))]);
  const fused = fs.existsSync(path.join(work, 'live_ball.csv')) ? readCsv(path.join(work, 'live_ball.csv')).length : 0;
  await page.waitForFunction(() => Number(document.querySelector('#v3-live-status').dataset.count || 0) > 0, null, { timeout: 10000 }).catch(() => {});
  const shown = Number((await page.getAttribute('#v3-live-status', 'data-count')) || 0);
  console.log(`live: the fusion node fused ${fused} positions; the 3D view received ${shown} (${await page.textContent('#v3-live-status')})`);
  await page.screenshot({ path: path.join(out, 'view3d_live.jpg'), quality: 70 });
  check(fused >= 10 && shown >= 0.8 * fused, `live positions from the fusion node shown in the 3D view (${shown} of ${fused})`);
  await page.click('#v3-live');
  await page.waitForFunction(() => /idle/.test(document.querySelector('#v3-live-status').textContent));

  lap('live');
  // ---- zones: a box drawn by clicking four corners on the field map
  await page.goto(url + '#zones');
  await page.waitForSelector('#zn-map[data-ready="1"]');
  const fieldModel = await api('/api/field?name=robocup-msl');
  const mapBox = await page.locator('#zn-map').boundingBox();
  const hl = fieldModel.length_m / 2 + fieldModel.surround_m;
  const hw = fieldModel.width_m / 2 + fieldModel.surround_m;
  const mapScale = Math.min(900 / (2 * hl), 600 / (2 * hw));
  const corners = [[-9, -3], [-6, -3], [-6, 3], [-9, 3]];
  for (const [x, y] of corners) {
    await page.mouse.click(mapBox.x + ((450 + x * mapScale) * mapBox.width) / 900, mapBox.y + ((300 - y * mapScale) * mapBox.height) / 600);
  }
  await page.fill('#zn-name', 'left box');
  await page.click('#zn-close');
  await page.click('#zn-save');
  await page.waitForFunction(() => /wrote/.test(document.querySelector('#zn-status').textContent));
  await page.screenshot({ path: path.join(out, 'zones.jpg'), quality: 70 });
  const savedZones = await api('/api/zones?path=zones.json');
  const zoneErr = Math.max(...savedZones[0].polygon.map(([x, y], i) => Math.hypot(x - corners[i][0], y - corners[i][1])));
  check(savedZones.length === 1 && savedZones[0].name === 'left box' && zoneErr < 0.1,
    `zone drawn on the map saved (corners within ${zoneErr.toFixed(3)} m)`);

  lap('zones');
  // ---- jobs: one runs to the end, one is cancelled; their states arrive as server events
  await page.goto(url + '#jobs');
  await page.waitForSelector('#page[data-ready="1"]');
  await page.selectOption('#jb-command', 'trajectory');
  await page.fill('#jb-args', '--in ball.csv --out flights_job.json');
  await page.click('#jb-start');
  await page.waitForSelector('#jb-list tr[data-state="done"]', { timeout: 30000 });
  check(fs.existsSync(path.join(work, 'flights_job.json')), 'a trajectory job ran to the end (flights_job.json written)');
  // The same job again would write over its output: refused until "Replace existing outputs".
  await page.click('#jb-start');
  await page.waitForFunction(() => /exists/.test(document.querySelector('#jb-status').textContent));
  check(await page.$$eval('#jb-list tr[data-job]', (rows) => rows.length) === 1,
    'a job whose output exists is refused (no second job)');
  await page.check('#jb-replace');
  await page.click('#jb-start');
  await page.waitForFunction(() => document.querySelectorAll('#jb-list tr[data-state="done"]').length === 2, null, { timeout: 30000 });
  check(true, 'with "Replace existing outputs" it runs again');
  await page.selectOption('#jb-command', 'synth');
  await page.fill('#jb-args', '--preset kick --frames 100000 --out long_scene');
  await page.click('#jb-start');
  await page.waitForSelector('#jb-list tr[data-state="running"] [data-cancel]');
  await page.click('#jb-list tr[data-state="running"] [data-cancel]');
  await page.waitForSelector('#jb-list tr[data-state="cancelled"]', { timeout: 30000 });
  await page.screenshot({ path: path.join(out, 'jobs.jpg'), quality: 70 });
  check(true, 'a running synth job was cancelled from the page');

  lap('jobs');
  // ---- players: the board plays with the video beside it (boxes of the same frame), heat map
  // A zone around the first player's start, so that the alert timeline has someone in it.
  const firstRow = readCsv(path.join(work, 'TRACKS.csv'))[0];
  const [zx, zy] = [Number(firstRow.x_m), Number(firstRow.y_m)];
  await api('/api/zones/save', { out: 'zones_players.json', zones: [{ name: 'start', polygon: [[zx - 1, zy - 1], [zx + 1, zy - 1], [zx + 1, zy + 1], [zx - 1, zy + 1]] }] });
  await page.goto(url + '#players');
  await page.waitForSelector('#page[data-ready="1"]');
  await page.selectOption('#pl-tracks', 'TRACKS.csv');
  await page.selectOption('#pl-zones', 'zones_players.json');
  await page.selectOption('#pl-video-file', 'players/side.avi');
  await page.click('#pl-load');
  await page.waitForSelector('#pl-board[data-frame]');
  await page.waitForSelector('#pl-video[data-frame]');
  const firstFrame = await page.getAttribute('#pl-board', 'data-frame');
  check(await page.getAttribute('#pl-video', 'data-frame') === String(Number(firstFrame) - 1),
    `video beside the board shows frame ${await page.getAttribute('#pl-video', 'data-frame')} for TRACKS frame ${firstFrame}`);
  await page.click('#pl-play');
  await page.waitForFunction((f) => Number(document.querySelector('#pl-board').dataset.frame) >= Number(f) + 5, firstFrame);
  await page.click('#pl-play');
  // Paused: the video catches up with the board.
  await page.waitForFunction(() => Number(document.querySelector('#pl-video').dataset.frame) === Number(document.querySelector('#pl-board').dataset.frame) - 1);
  const videoStats = await page.evaluate(() => {
    const c = document.querySelector('#pl-video');
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let bright = 0;
    for (let i = 0; i < d.length; i += 4) if (d[i] + d[i + 1] + d[i + 2] > 60) ++bright;
    return bright / (d.length / 4);
  });
  check(videoStats > 0.2, `video frame drawn beside the board (${(100 * videoStats).toFixed(0)} % of pixels lit)`);
  const players = readCsv(path.join(work, 'TRACKS.csv'));
  const nFrames = new Set(players.map((r) => r.frame)).size;
  const heatTotal = Number(await page.getAttribute('#pl-heat', 'data-total-s'));
  const heatMax = Number(await page.getAttribute('#pl-heat', 'data-max-s'));
  const nIds = new Set(players.map((r) => r.id)).size;
  // Every sample counts one frame step (the scene's frames are evenly spaced).
  const times = [...new Set(players.map((r) => Number(r.time_s)))].sort((a, b) => a - b);
  const step = times[1] - times[0];
  console.log(`players: heat map ${heatTotal.toFixed(2)} s in all (${players.length} samples x ${step.toFixed(3)} s), busiest cell ${heatMax.toFixed(2)} s`);
  check(Math.abs(heatTotal - players.length * step) < 1e-3 * players.length && heatMax > 0 && heatMax <= nFrames * step + 1e-6,
    `heat map holds every sample's time (${heatTotal.toFixed(2)} s for ${nIds} players)`);
  await page.selectOption('#pl-heat-id', players[0].id);
  const oneTotal = Number(await page.getAttribute('#pl-heat', 'data-total-s'));
  check(oneTotal < heatTotal && oneTotal > 0, `heat map of one player (${oneTotal.toFixed(2)} s)`);
  await page.screenshot({ path: path.join(out, 'players.jpg'), quality: 70, fullPage: true });
  check(await page.locator('#pl-chart .uplot').count() === 1, 'speed chart drawn');
  const libStats = await api('/api/players/stats', { tracks: 'TRACKS.csv', zones: 'zones_players.json' });
  const tableRows = await page.$$eval('#pl-table tr[data-id]', (rows) => rows.map((r) => [Number(r.dataset.id), Number(r.dataset.distance)]));
  check(tableRows.length === libStats.players.length && libStats.players.length === nIds &&
    tableRows.every(([id, d]) => libStats.players.some((p) => p.id === id && p.distance_m === d)),
    `the table shows fieldvision stats' distance and speeds of ${tableRows.length} players`);
  const alertCount = Number(await page.getAttribute('#pl-alerts', 'data-events'));
  check(alertCount === libStats.events.length && alertCount >= 1 && libStats.events.some((e) => e.id === Number(firstRow.id) && e.zone === 'start'),
    `zone alerts on the timeline (${alertCount}: ${libStats.events.map((e) => `id ${e.id} ${e.enter_s}-${e.exit_s} s`).join(', ')})`);
  check(true, `tactical board plays (frame ${firstFrame} -> ${await page.getAttribute('#pl-board', 'data-frame')})`);
  // Export: the statistics as CSV (the table's numbers), the alerts, the heat map shown with its
  // scale and title, written into a folder of the working folder.
  await page.fill('#pl-export-out', 'players_export');
  await page.click('#pl-export');
  await page.waitForSelector('#pl-export-status[data-wrote]');
  const exported = path.join(work, 'players_export');
  const csvPlayers = readCsv(path.join(exported, 'players.csv'));
  check(csvPlayers.length === tableRows.length && tableRows.every(([id, d]) => csvPlayers.some((p) => Number(p.id) === id && Math.abs(Number(p.distance_m) - d) < 0.01)),
    `export: players.csv holds the table's ${csvPlayers.length} players and distances`);
  check(readCsv(path.join(exported, 'zone_alerts.csv')).length === alertCount, `export: zone_alerts.csv holds the ${alertCount} alerts`);
  const pngSize = (f) => {
    const b = fs.readFileSync(path.join(exported, f));
    return b.subarray(1, 4).toString() === 'PNG' ? [b.readUInt32BE(16), b.readUInt32BE(20)] : null;
  };
  const [heatW, heatH] = await page.$eval('#pl-heat', (c) => [c.width, c.height + document.querySelector('#pl-heat-legend').height]);
  const pageHeat = pngSize('page_heatmap.png');
  check(pageHeat && pageHeat[0] === heatW && pageHeat[1] > heatH, `export: the page's heat map with its scale (page_heatmap.png ${pageHeat})`);
  check(['heatmap_all.png', 'page_board.png', 'page_speed.png', 'index.html', 'stats.json'].every((f) => fs.existsSync(path.join(exported, f))),
    'export: stats heat maps, board, speed chart, report');
  // Again into that folder: refused (the earlier export is kept) until the folder is replaced.
  const statsBefore = fs.readFileSync(path.join(exported, 'stats.json'));
  await page.click('#pl-export');
  await page.waitForSelector('#pl-export-status.error');
  const refusedText = await page.textContent('#pl-export-status');
  check(/not empty/.test(refusedText) && fs.readFileSync(path.join(exported, 'stats.json')).equals(statsBefore),
    `export: a folder that is not empty is refused, kept as it was (${refusedText})`);
  await page.check('#pl-export-replace');
  await page.click('#pl-export');
  await page.waitForFunction(() => /^wrote \d+ files/.test(document.querySelector('#pl-export-status').textContent));
  check(fs.existsSync(path.join(exported, 'players.csv')) && fs.readdirSync(work).every((f) => !f.startsWith('.players_export')),
    'export: with "Replace an earlier export" ticked it is written again');
  lap('players');
  check(consoleErrors.length === 0, `no errors in the page's console${consoleErrors.length ? ': ' + consoleErrors.join(' | ') : ''}`);
} catch (e) {
  failures.push(String(e));
  console.log(`FAIL ${e}`);
  await page.screenshot({ path: path.join(out, 'failure.jpg'), quality: 70 }).catch(() => {});
} finally {
  for (const c of children) if (c.exitCode === null) c.kill();
  await browser.close();
}
console.log(failures.length ? `${failures.length} failure(s); screenshots in ${out}` : `all passed; screenshots in ${out}`);
process.exit(failures.length ? 1 : 0);
