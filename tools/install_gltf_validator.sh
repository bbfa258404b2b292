#!/usr/bin/env bash
# Installs the Khronos glTF-Validator (the npm package gltf-validator, pinned)
# into .cache/gltf-validator, where the glTF export's test finds it
# (tests/python/test_poses_and_export.py). Needs node and npm (Debian's
# nodejs and npm; .ci/install-deps installs them). CI runs it (.ci/run) and
# sets MMVK_REQUIRE_GLTF_VALIDATOR=1, so the test fails instead of skipping
# when the validator is missing. The package's published versions are all
# 2.0.0-dev.*: one of them, exactly.
set -euo pipefail
cd "$(dirname "$0")/.."
version=2.0.0-dev.3.10
npm install --prefix .cache/gltf-validator --no-audit --no-fund --no-save --loglevel=error "gltf-validator@$version"
node -e "console.log('gltf-validator', require('./.cache/gltf-validator/node_modules/gltf-validator').version())"
