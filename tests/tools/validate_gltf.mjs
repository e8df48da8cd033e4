#!/usr/bin/env node
// SPDX-License-Identifier: GPL-3.0-or-later
// Runs the Khronos glTF validator (npm package gltf-validator) on each file given.
//
//   npm install --prefix tests/tools          # once; installs the pinned validator
//   node tests/tools/validate_gltf.mjs [--strict] file.gltf file.glb ...
//
// Prints the number of errors, warnings, infos and hints of each file and every message.
// Exit status: 0 when no file has errors (with --strict: no errors and no warnings),
// 1 when some file has them, 2 when a file cannot be read or validated at all.
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { validateBytes, version } from 'gltf-validator';

const severityNames = ['error', 'warning', 'info', 'hint'];

async function validate(file) {
  const bytes = new Uint8Array(await readFile(file));
  const dir = path.dirname(path.resolve(file));
  return validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,  // report every issue
    writeTimestamp: false,
    // External buffers (.bin next to a .gltf) are validated too.
    externalResourceFunction: async (uri) =>
      new Uint8Array(await readFile(path.resolve(dir, decodeURIComponent(uri)))),
  });
}

const args = process.argv.slice(2);
const strict = args.includes('--strict');
const files = args.filter((a) => a !== '--strict');
if (files.length === 0) {
  console.error('usage: validate_gltf.mjs [--strict] FILE.gltf|FILE.glb ...');
  process.exit(2);
}

let status = 0;
for (const file of files) {
  let report;
  try {
    report = await validate(file);
  } catch (e) {
    console.error(`${file}: cannot validate: ${e}`);
    status = 2;
    continue;
  }
  const issues = report.issues;
  console.log(
    `${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
      `${issues.numInfos} infos, ${issues.numHints} hints (gltf-validator ${version()})`);
  for (const m of issues.messages) {
    const where = m.pointer ?? (m.offset !== undefined ? `@${m.offset}` : '');
    console.log(`  ${severityNames[m.severity] ?? m.severity} ${m.code} ${where}: ${m.message}`);
  }
  if (issues.numErrors > 0 || (strict && issues.numWarnings > 0)) status = Math.max(status, 1);
}
process.exit(status);
