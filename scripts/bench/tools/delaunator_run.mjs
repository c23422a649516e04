// pdt benchmark helper: the npm package delaunator on a pdt point file
// ("x y" per line).  Copied at bench time into build/bench/ (next to its
// node_modules) by scripts/bench/10-triangulate.sh.  Prints one JSON line:
// points, triangles, seconds spent reading and building.
import { readFileSync } from 'node:fs';
import Delaunator from 'delaunator';

const t0 = performance.now();
const text = readFileSync(process.argv[2], 'utf8');
const nums = text.split(/\s+/).filter((s) => s.length > 0);
const coords = new Float64Array(nums.length);
for (let i = 0; i < nums.length; i++) coords[i] = +nums[i];
const t1 = performance.now();
const d = new Delaunator(coords);
const t2 = performance.now();
console.log(JSON.stringify({ tool: 'delaunator', n: coords.length / 2,
                             triangles: d.triangles.length / 3,
                             read: (t1 - t0) / 1000, build: (t2 - t1) / 1000 }));
