#!/usr/bin/env node
// Runs the Khronos glTF validator (npm package gltf-validator, installed into tools/node_modules by
// scripts/install-deps.sh) on each file given.
//
//   node scripts/validate-gltf.mjs [--json] [--all] [--max-issues N] FILE...
//
// Prints, per file, "FILE: E errors, W warnings, I infos, H hints" followed by the error and warning messages
// (with --all, the infos and hints too);
// with --json, one JSON object per file per line instead:
//   {"file", "validatorVersion", "errors", "warnings", "infos", "hints", "messages": [{code, severity, message, pointer}]}
// (messages: errors and warnings only, unless --all). Exit code: 0 when no file has an error, 1 when one has (or cannot be
// read), 2 for a bad command line or a missing validator. HEMIBAKE_GLTF_VALIDATOR may name the package folder.
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const packageDir = process.env.HEMIBAKE_GLTF_VALIDATOR || path.join(here, '..', 'tools', 'node_modules', 'gltf-validator');

const args = process.argv.slice(2);
let json = false;
let all = false;
let maxIssues = 100;
const files = [];
for (let i = 0; i < args.length; ++i) {
  if (args[i] === '--json') json = true;
  else if (args[i] === '--all') all = true;
  else if (args[i] === '--max-issues' && i + 1 < args.length) maxIssues = Number(args[++i]);
  else if (args[i] === '--help' || args[i] === '-h') {
    console.log('usage: node scripts/validate-gltf.mjs [--json] [--all] [--max-issues N] FILE...');
    process.exit(0);
  } else if (args[i].startsWith('--')) {
    console.error(`validate-gltf: unknown option ${args[i]}`);
    process.exit(2);
  } else files.push(args[i]);
}
if (files.length === 0 || !(maxIssues >= 0)) {
  console.error('usage: node scripts/validate-gltf.mjs [--json] [--all] [--max-issues N] FILE...');
  process.exit(2);
}

let validator;
try {
  validator = createRequire(import.meta.url)(packageDir);
} catch (e) {
  console.error(`validate-gltf: the glTF validator is not installed at ${packageDir} (run scripts/install-deps.sh)`);
  process.exit(2);
}

const severityName = ['error', 'warning', 'info', 'hint'];
let failed = false;
for (const file of files) {
  let report;
  try {
    const bytes = new Uint8Array(fs.readFileSync(file));
    report = await validator.validateBytes(bytes, {
      uri: path.basename(file),
      maxIssues,
      externalResourceFunction: (uri) =>
        new Promise((resolve, reject) => {
          fs.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
            err ? reject(err.toString()) : resolve(new Uint8Array(data)));
        }),
    });
  } catch (e) {
    failed = true;
    const message = `${file}: cannot be validated: ${e && e.message ? e.message : e}`;
    if (json) console.log(JSON.stringify({ file, error: message, errors: 1, warnings: 0, infos: 0, hints: 0, messages: [] }));
    else console.error(message);
    continue;
  }
  const issues = report.issues;
  const messages = issues.messages
    .filter((m) => all || m.severity <= 1)
    .map((m) => ({ code: m.code, severity: severityName[m.severity], message: m.message, pointer: m.pointer ?? m.offset }));
  if (issues.numErrors > 0) failed = true;
  if (json) {
    console.log(JSON.stringify({
      file, validatorVersion: report.validatorVersion, errors: issues.numErrors, warnings: issues.numWarnings,
      infos: issues.numInfos, hints: issues.numHints, messages,
    }));
  } else {
    console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ${issues.numInfos} infos, ${issues.numHints} hints`);
    for (const m of messages) console.log(`  ${m.severity} ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  }
}
process.exit(failed ? 1 : 0);
