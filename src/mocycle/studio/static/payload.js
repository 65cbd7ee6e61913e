// The studio's binary payload (studio/payload.py): "MOCY", uint32 header length, JSON header, float32 blocks.
export function decode(buffer) {
  const view = new DataView(buffer);
  const magic = String.fromCharCode(...new Uint8Array(buffer, 0, 4));
  if (magic !== "MOCY") throw new Error("not a mocycle payload");
  const n = view.getUint32(4, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 8, n)));
  const arrays = {};
  for (const [name, b] of Object.entries(header.blocks)) {
    const count = b.shape.reduce((a, c) => a * c, 1);
    arrays[name] = new Float32Array(buffer, 8 + n + b.offset, count);
    arrays[name].shape = b.shape;
  }
  return { header, arrays };
}

// the server's token (studio/guard.py), in the page the studio served; none in an offline report
export function token() {
  const meta = typeof document === "undefined" ? null : document.querySelector('meta[name="mocycle-token"]');
  return meta ? meta.content : "";
}

export async function fetchPayload(url) {
  const r = await fetch(url, { headers: { "X-Mocycle-Token": token() } });
  if (!r.ok) throw new Error((await r.json().catch(() => ({}))).error || `${url}: ${r.status}`);
  return decode(await r.arrayBuffer());
}
