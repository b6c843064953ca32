import { defineConfig } from 'vitest/config';

// The page is served by `costar serve` from web/dist. For development, `npm run dev` serves it
// with hot reload and forwards /api (HTTP and the WebSocket) to a server on port 8080.
export default defineConfig({
  esbuild: { jsx: 'automatic' },
  build: { outDir: 'dist', emptyOutDir: true, chunkSizeWarningLimit: 2000 },
  server: { proxy: { '/api': { target: 'http://127.0.0.1:8080', ws: true } } },
  test: { environment: 'node', include: ['test/**/*.test.ts'] },
});
