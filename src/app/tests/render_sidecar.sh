#!/usr/bin/env bash
# `panoptes render` and field sidecars (issue 41; docs/formats.md "Field sidecars"): a .npy whose sidecar
# says z is depth (up_axis z_down) is shown with z = 0 at the top of the picture without any option, and
# the manifest records the sidecar's units, times and field; the same array without its sidecar keeps
# the old default (z up). Options that contradict a sidecar, a sidecar of another shape, a series with
# and without sidecars and a malformed sidecar are refused, naming the sidecar and the key.
set -euo pipefail
panoptes=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "render_sidecar.sh: $*" >&2; exit 1; }

# A 16x12x10 volume (x, y, z) that is 1 in a layer under z = 0 (k < 3) and 0 below: a "surface layer".
/usr/bin/python3 - "$tmp" <<'EOF'
import json, struct, sys
tmp = sys.argv[1]
nz, ny, nx = 10, 12, 16
def npy(path, values, shape=(nz, ny, nx)):
    header = "{'descr': '<f4', 'fortran_order': False, 'shape': %s, }" % (str(tuple(shape)),)
    header += " " * (63 - (10 + len(header)) % 64) + "\n"
    with open(path, "wb") as f:
        f.write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode())
        f.write(struct.pack("<%df" % len(values), *values))
layer = [1.0 if k < 3 else 0.0 for k in range(nz) for j in range(ny) for i in range(nx)]
for name in ("layer", "plain", "later"):
    npy(f"{tmp}/{name}.npy", layer)
def sidecar(name, **changes):
    s = {"format": "panoptes field sidecar", "version": 1, "data": name + ".npy", "field": "phi_p", "field_units": "1/s",
         "dims": [nx, ny, nz], "origin": [0, 0, 0], "spacing": [1, 1, 1], "length_units": "m", "up_axis": "z_down",
         "time": 2.5, "time_units": "s", "step": 50}
    s.update(changes)
    with open(f"{tmp}/{name}.json", "w") as f:
        json.dump(s, f)
sidecar("layer")
sidecar("later", time=1.5)  # earlier than layer's 2.5: out of order after it
# One camera beside the domain (a side view along +y), looking at its centre with the sky up.
with open(f"{tmp}/side.txt", "w") as f:
    f.write("7.5 -60 4.5\n")
EOF

render() { "$panoptes" render "$@" --rig "file:$tmp/side.txt" --task volume:grayscale:0:1 --no-outline --size 48x40 -q > /dev/null; }
# Brightness of the upper and the lower half of the first frame of camera 0 of a database.
halves() {
  rm -rf "$tmp/frames"
  printf 't=0 camera=0\n' > "$tmp/script.txt"
  "$panoptes" play "$1" --headless --script "$tmp/script.txt" --paused --frames-out "$tmp/frames" > /dev/null
  /usr/bin/python3 - "$tmp/frames/frame_000000.png" <<'EOF'
import struct, sys, zlib
data = open(sys.argv[1], "rb").read()
pos, idat, (w, h, depth, colour) = 8, b"", (0, 0, 0, 0)
while pos < len(data):  # a minimal PNG reader: 8-bit RGB or RGBA, the five filters
    n, kind = struct.unpack(">I4s", data[pos:pos + 8])
    body = data[pos + 8:pos + 8 + n]
    if kind == b"IHDR":
        w, h, depth, colour = struct.unpack(">IIBB", body[:10])
    elif kind == b"IDAT":
        idat += body
    pos += 12 + n
assert depth == 8 and colour in (2, 6), (depth, colour)
bpp = 3 if colour == 2 else 4
raw, stride, rows, prev = zlib.decompress(idat), w * bpp, [], bytearray(w * bpp)
for y in range(h):
    f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
    for i in range(stride):
        a = line[i - bpp] if i >= bpp else 0
        b, c = prev[i], prev[i - bpp] if i >= bpp else 0
        p = a + b - c
        pred = [0, a, b, (a + b) // 2, a if abs(p - a) <= abs(p - b) and abs(p - a) <= abs(p - c) else (b if abs(p - b) <= abs(p - c) else c)][f]
        line[i] = (line[i] + pred) & 255
    rows.append(line)
    prev = line
luma = [sum(r[i] + r[i + 1] + r[i + 2] for i in range(0, stride, bpp)) for r in rows]
print(sum(luma[:h // 2]), sum(luma[h - h // 2:]))
EOF
}

# With the sidecar: z_down, the layer under z = 0 on top; units, times and the field from the sidecar.
render "$tmp/layer.npy" --out "$tmp/with"
read -r top bottom < <(halves "$tmp/with")
echo "with the sidecar (z_down): light in the upper half $top, lower half $bottom"
[ "$top" -gt $((4 * bottom)) ] || fail "with its sidecar (z_down) the surface layer is not on top: upper half $top, lower half $bottom"
/usr/bin/python3 - "$tmp/with/panoptes.json" <<'EOF' || fail "manifest of the render with a sidecar"
import json, sys
m = json.load(open(sys.argv[1]))
got = (m["domain"].get("up_axis"), m["domain"].get("units"), m.get("time_units"), m.get("times"),
       [(f["name"], f["units"]) for f in m.get("fields", [])], m["domain"]["spacing"])
want = ("z_down", "m", "s", [2.5], [("phi_p", "1/s")], [1, 1, 1])
if got != want:
    sys.exit(f"manifest: {got}, expected {want}")
if "--up-axis z_down" not in m["provenance"]["command_line"]:
    sys.exit("the recorded command line does not say the up axis rendered: " + m["provenance"]["command_line"])
EOF
# Without it: as before issue 41, z up, so the layer is at the bottom.
render "$tmp/plain.npy" --out "$tmp/without"
read -r top bottom < <(halves "$tmp/without")
echo "without it (z up): light in the upper half $top, lower half $bottom"
[ "$bottom" -gt $((4 * top)) ] || fail "without a sidecar (z up) the layer at z = 0 is not at the bottom: upper half $top, lower half $bottom"
# A pattern that also matches the sidecar ('layer*': layer.npy, layer.json) renders the volume alone.
"$panoptes" render "$tmp/layer*" --rig "file:$tmp/side.txt" --size 48x40 -q --out "$tmp/glob" > "$tmp/out.txt"
grep -q "1 frames of 48x40" "$tmp/out.txt" || fail "pattern with the sidecar: $(cat "$tmp/out.txt")"
# An option that agrees with the sidecar is accepted.
render "$tmp/layer.npy" --up-axis z_down --spacing 1,1,1 --origin 0,0,0 --out "$tmp/agree"

expect_error() {  # expect_error PATTERN ARGS...: exit 1 and one error line matching PATTERN
  local pattern=$1; shift
  if render "$@" 2> "$tmp/err.txt" > /dev/null; then fail "accepted: $*"; fi
  grep -q "panoptes: error: .*$pattern" "$tmp/err.txt" || fail "for '$*' expected /$pattern/, got: $(cat "$tmp/err.txt")"
  [ "$(wc -l < "$tmp/err.txt")" -eq 1 ] || fail "more than one error line: $(cat "$tmp/err.txt")"
}
expect_error 'layer.json: up_axis: "z_down" contradicts --up-axis z_up' "$tmp/layer.npy" --up-axis z_up --out "$tmp/e1"
expect_error 'layer.json: spacing: \[1, 1, 1\] contradicts --spacing 2,1,1' "$tmp/layer.npy" --spacing 2,1,1 --out "$tmp/e2"
expect_error 'layer.json: origin: \[0, 0, 0\] contradicts --origin 0,0,5' "$tmp/layer.npy" --origin 0,0,5 --out "$tmp/e3"
expect_error 'plain.npy: has no sidecar' "$tmp/layer.npy" "$tmp/plain.npy" --out "$tmp/e4"
expect_error 'later.json: time: 1.5 comes after .*layer.json at time 2.5' "$tmp/layer.npy" "$tmp/later.npy" --out "$tmp/e5"
expect_error 'layer.json: describes a volume on a uniform grid, but --grid' "$tmp/layer.npy" --grid "$tmp/g.toml" --out "$tmp/e6"
cp "$tmp/layer.json" "$tmp/good.json"
sed 's/"dims": \[16, 12, 10\]/"dims": [16, 12, 11]/' "$tmp/good.json" > "$tmp/layer.json"
expect_error 'layer.json: dims: \[16, 12, 11\] (points along x, y, z), but .*layer.npy holds 16x12x10 points' "$tmp/layer.npy" --out "$tmp/e7"
sed 's/"up_axis": "z_down"/"up_axis": "depth"/' "$tmp/good.json" > "$tmp/layer.json"
expect_error 'layer.json: up_axis: expected "z_up" or "z_down" (z is depth), got "depth"' "$tmp/layer.npy" --out "$tmp/e8"
sed 's/"spacing": \[1, 1, 1\], //' "$tmp/good.json" > "$tmp/layer.json"
expect_error 'layer.json: spacing: expected an array of 3 numbers > 0, but the key is missing' "$tmp/layer.npy" --out "$tmp/e9"
echo '{"version": 1, "dims": [16, 12' > "$tmp/layer.json"
expect_error 'layer.json: malformed JSON' "$tmp/layer.npy" --out "$tmp/e10"
for e in e1 e2 e3 e4 e5 e6 e7 e8 e9 e10; do [ ! -e "$tmp/$e" ] || fail "a refused render left $tmp/$e behind"; done
echo "render_sidecar: ok"
