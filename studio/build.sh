#!/usr/bin/env bash
# Builds the studio's front end into studio/dist (npm ci + vite build) when npm is present and
# dist is older than the sources; otherwise says what is missing (the server's page says so too).
set -euo pipefail
cd "$(dirname "$0")"
if ! command -v npm >/dev/null 2>&1 || ! command -v node >/dev/null 2>&1; then
  echo "studio: Node.js/npm not found: the web front end is not built (scripts/install-deps.sh installs them)"
  exit 0
fi
if [ ! -d node_modules ] || [ package-lock.json -nt node_modules/.package-lock.json ]; then
  if ! npm ci --no-audit --no-fund --loglevel=error; then
    echo "studio: 'npm ci' failed (no access to the npm registry?): the web front end is not built"
    exit 0
  fi
fi
if [ -f dist/index.html ] && [ -z "$(find src index.html vite.config.ts tsconfig.json package-lock.json -newer dist/index.html -print -quit)" ]; then
  exit 0
fi
npx tsc --noEmit -p .
npx vite build --logLevel warn
echo "studio: built studio/dist"
