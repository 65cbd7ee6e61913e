// The JavaScript half of mocycle's glTF tests (tests/io/test_gltf.py runs it; `make js` installs its packages).
//   node check_glb.mjs FILE.glb [TIME ...]
// prints one JSON object: the Khronos glTF validator's report (counts and messages) and, as three.js loads the
// file (GLTFLoader) and plays its first clip (AnimationMixer), the clip's name and duration, the scene's
// extras, and every node's world position at each TIME (seconds), by glTF node index.
import { readFileSync } from "node:fs";
import validator from "gltf-validator";
import { AnimationMixer, LoopOnce, Vector3 } from "three";
import { GLTFLoader } from "three/examples/jsm/loaders/GLTFLoader.js";

const [file, ...timeArgs] = process.argv.slice(2);
const bytes = readFileSync(file);
const report = await validator.validateBytes(new Uint8Array(bytes), { maxIssues: 100 });
const arrayBuffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
const gltf = await new Promise((resolve, reject) => new GLTFLoader().parse(arrayBuffer, "", resolve, reject));

const clip = gltf.animations[0];
const mixer = new AnimationMixer(gltf.scene);
const action = mixer.clipAction(clip);
action.setLoop(LoopOnce, 1);
action.clampWhenFinished = true;
action.play();

const nodes = {};
gltf.scene.traverse((object) => {
  const association = gltf.parser.associations.get(object);
  if (association && association.nodes !== undefined) nodes[association.nodes] = object;
});
const positions = [];
for (const t of timeArgs.map(Number)) {
  mixer.setTime(t);
  gltf.scene.updateMatrixWorld(true);
  const frame = {};
  for (const [index, object] of Object.entries(nodes)) frame[index] = object.getWorldPosition(new Vector3()).toArray();
  positions.push(frame);
}
const bones = Object.entries(nodes).filter(([, o]) => o.isBone).length;
console.log(JSON.stringify({
  validator: { ...report.issues, version: report.validatorVersion },
  clip: { name: clip.name, duration: clip.duration, tracks: clip.tracks.length },
  bones,
  skinnedMeshes: (() => { let n = 0; gltf.scene.traverse((o) => { if (o.isSkinnedMesh) n += 1; }); return n; })(),
  sceneExtras: gltf.scene.userData,
  positions,
}));
