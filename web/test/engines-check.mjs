// Every npm package the project installs (web/package-lock.json) must accept
// the Node.js and npm that Debian 12 ships, whatever node runs this check: a
// development machine with a newer node would otherwise install and pass with
// a package that a fresh Debian 12 refuses (playwright-core 1.62 and later
// declare node >= 20). scripts/cleanroom.sh proves the same on a real
// Debian 12 root; this check says it in seconds, on any machine.
//
// usage: node engines-check.mjs PACKAGE-LOCK.json
import { readFileSync } from "node:fs";
import semver from "semver";

// Debian 12's candidates (apt-cache madison nodejs npm, bookworm and
// bookworm-security, 2026-11): nodejs 18.20.4+dfsg-1~deb12u3, npm 9.2.0~ds1-1.
const DEBIAN12 = { node: "18.20.4", npm: "9.2.0" };

const lockPath = process.argv[2];
if (!lockPath) {
  console.error("usage: node engines-check.mjs PACKAGE-LOCK.json");
  process.exit(2);
}
const lock = JSON.parse(readFileSync(lockPath, "utf8"));
const problems = [];
let checked = 0;
for (const [path, entry] of Object.entries(lock.packages ?? {})) {
  if (!path) continue; // the project itself
  checked++;
  for (const [tool, version] of Object.entries(DEBIAN12)) {
    const range = entry.engines?.[tool];
    if (range && !semver.satisfies(version, range)) {
      problems.push(`${path}@${entry.version}: engines.${tool} "${range}" rejects Debian 12's ${tool} ${version}`);
    }
  }
}
if (checked === 0) problems.push(`${lockPath}: no packages listed`);
for (const p of problems) console.error(p);
console.log(`${checked} packages checked against Debian 12's node ${DEBIAN12.node} and npm ${DEBIAN12.npm}: ` +
            (problems.length ? `${problems.length} refused` : "all accepted"));
process.exit(problems.length ? 1 : 0);
