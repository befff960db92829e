#!/usr/bin/env node
// Validates one glTF/GLB file with the Khronos glTF validator and prints the report
// as JSON on stdout. Exit code: 0 when the report has no errors, 1 when it has errors,
// 2 on usage or I/O problems.
// Install first: npm ci --prefix tools/gltf-validator
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

const file = process.argv[2];
if (!file) {
  console.error('usage: node validate.js FILE.glb|FILE.gltf');
  process.exit(2);
}
let data;
try {
  data = new Uint8Array(fs.readFileSync(file));
} catch (e) {
  console.error(`cannot read ${file}: ${e.message}`);
  process.exit(2);
}
const dir = path.dirname(file);
validator
  .validateBytes(data, {
    uri: path.basename(file),
    maxIssues: 0,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.resolve(dir, decodeURIComponent(uri)), (err, d) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(d)));
      }),
  })
  .then((report) => {
    console.log(JSON.stringify(report, null, 2));
    process.exit(report.issues.numErrors > 0 ? 1 : 0);
  })
  .catch((e) => {
    console.error(`validator failed on ${file}: ${e}`);
    process.exit(2);
  });
