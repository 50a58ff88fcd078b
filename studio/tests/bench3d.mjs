// The 3D view's benchmark (#bench3d) in Debian's headless chromium, as the browser test runs it,
// for several scenes in one browser: an empty scene (the renderer's and the compositor's floor on
// this machine), the field and cameras alone, and the field with an N-point track. Prints, per
// scene, the frames shown per second while the view turns and the render + GPU-finish cost.
// Usage: node bench3d.mjs URL [POINTS=10000] [REPEATS=2]   (URL of a running `fieldvision studio`)
import { launchChromium } from './chromium.mjs';

const [url, points = '10000', repeats = '2'] = process.argv.slice(2);
if (!url) {
  console.error('usage: node bench3d.mjs URL [POINTS] [REPEATS]');
  process.exit(2);
}
const browser = await launchChromium('fv-bench3d-chromium-');
const page = browser.page;
const scenes = [['empty', 'scene=empty&points=0'], ['field + cameras', 'points=0'], [`field + cameras + ${points} points`, `points=${points}`]];
try {
  for (let r = 0; r < Number(repeats); ++r) {
    for (const [name, query] of scenes) {
      const u = new URL(url);
      u.search = query;
      u.hash = 'bench3d';
      await page.goto('about:blank');
      await page.goto(u.toString());
      await page.waitForSelector('#v3-status[data-fps]', { timeout: 120000 });
      const b = JSON.parse(await page.getAttribute('#v3-status', 'data-bench'));
      console.log(`${name.padEnd(34)} ${String(b.paced_fps).padStart(5)} frames/s shown; render ${b.render_ms_median} ms ` +
        `(p95 ${b.render_ms_p95}); canvas ${b.canvas ?? '?'}, ${b.points_drawn ?? '?'} points and ${b.segments ?? '?'} line segments drawn; ${b.renderer.replace(/ \(0x[0-9A-F]+\)|ANGLE \(Google, |, SwiftShader driver\)/g, '')}`);
    }
  }
} finally {
  await browser.close();
}
