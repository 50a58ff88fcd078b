// Builds the studio's pages into dist/, which `fieldvision studio` serves. Relative asset paths,
// everything bundled (three.js, uPlot): nothing is loaded from a CDN.
import { defineConfig } from 'vite';

export default defineConfig({
  base: './',
  build: { outDir: 'dist', emptyOutDir: true, chunkSizeWarningLimit: 1500 },
});
