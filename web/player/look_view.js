// The perspective cut-out of an equirectangular (360° × 180°) frame, drawn by WebGL2: the decoded
// VideoFrame is the texture and a fragment shader maps every pixel's ray to longitude/latitude — the
// same mapping as the desktop's look mesh (src/ui/look_mesh.cpp) and its CPU reference
// player::perspective_cutout (longitude wraps, bilinear sampling, latitude clamped at the poles).
import { lookBasis } from "./look.js";

const VERTEX = `#version 300 es
in vec2 p;
out vec2 ndc;
void main() { ndc = p; gl_Position = vec4(p, 0.0, 1.0); }`;

// Directions are in the camera's own frame: x = right, y = up, z = forward.
const FRAGMENT = `#version 300 es
precision highp float;
in vec2 ndc;
uniform vec3 F, R, U;
uniform vec2 tanHalf;
uniform sampler2D tex;
out vec4 colour;
const float PI = 3.14159265358979;
void main() {
  vec3 d = F + R * (ndc.x * tanHalf.x) + U * (ndc.y * tanHalf.y);
  float lon = atan(d.x, d.z), lat = atan(d.y, length(d.xz));
  colour = vec4(texture(tex, vec2((lon / PI + 1.0) * 0.5, 0.5 - lat / PI)).rgb, 1.0);
}`;

/// player::look_basis of a camera's own frame, in the shader's coordinates (x = right, y = up, z =
/// forward). Not look.js's lookBasis on unit vectors: that takes up = right × forward, which in these
/// left-handed coordinates is −y (the cut-out came out upside down, pitch mirrored on screen).
function viewInCameraFrame(look) {
  const r = Math.PI / 180, cy = Math.cos(look.yaw * r), sy = Math.sin(look.yaw * r), cp = Math.cos(look.pitch * r), sp = Math.sin(look.pitch * r);
  const heading = [sy, 0, cy];  // forward·cos(yaw) + right·sin(yaw)
  return {
    right: [cy, 0, -sy],
    forward: [heading[0] * cp, sp, heading[2] * cp],
    up: [-heading[0] * sp, cp, -heading[2] * sp],  // up·cos(pitch) − heading·sin(pitch) = right × forward in the world
  };
}

export class LookView {
  /// Throws Error when the browser has no WebGL2.
  constructor(canvas) {
    // preserveDrawingBuffer: the cut-out is drawn only when the frame or the look changed, and the
    // tests and the latency benchmark read its pixels between draws.
    const gl = canvas.getContext("webgl2", { antialias: false, preserveDrawingBuffer: true, alpha: false });
    if (!gl) throw new Error("this browser has no WebGL2: 360° frames cannot be shown as a cut-out");
    this.canvas = canvas;
    this.gl = gl;
    const shader = (type, src) => {
      const s = gl.createShader(type);
      gl.shaderSource(s, src);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(`look shader: ${gl.getShaderInfoLog(s)}`);
      return s;
    };
    const prog = gl.createProgram();
    gl.attachShader(prog, shader(gl.VERTEX_SHADER, VERTEX));
    gl.attachShader(prog, shader(gl.FRAGMENT_SHADER, FRAGMENT));
    gl.linkProgram(prog);
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(`look shader: ${gl.getProgramInfoLog(prog)}`);
    this.prog = prog;
    this.u = Object.fromEntries(["F", "R", "U", "tanHalf", "tex"].map((n) => [n, gl.getUniformLocation(prog, n)]));
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    const buf = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, buf);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-1, -1, 1, -1, -1, 1, 1, 1]), gl.STATIC_DRAW);
    const loc = gl.getAttribLocation(prog, "p");
    gl.enableVertexAttribArray(loc);
    gl.vertexAttribPointer(loc, 2, gl.FLOAT, false, 0, 0);
    this.tex = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, this.tex);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.REPEAT);  // longitude wraps
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
    this.hasFrame = false;
  }

  /// Waits until the queued drawing is done (reads one pixel).
  finish() {
    const gl = this.gl;
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, this.pixel ?? (this.pixel = new Uint8Array(4)));
  }

  /// Uploads a decoded frame (VideoFrame, canvas or image) as the panorama.
  upload(source) {
    const gl = this.gl;
    gl.bindTexture(gl.TEXTURE_2D, this.tex);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, gl.RGBA, gl.UNSIGNED_BYTE, source);
    this.hasFrame = true;
  }

  /// Draws the cut-out of the look {yaw, pitch, fov} (vertical field of view, square pixels).
  draw(look) {
    const gl = this.gl, w = this.canvas.width, h = this.canvas.height;
    gl.viewport(0, 0, w, h);
    if (!this.hasFrame) { gl.clearColor(0, 0, 0, 1); gl.clear(gl.COLOR_BUFFER_BIT); return; }
    const v = viewInCameraFrame(look);
    const t = Math.tan((look.fov * Math.PI) / 360);
    gl.useProgram(this.prog);
    gl.uniform3fv(this.u.F, v.forward);
    gl.uniform3fv(this.u.R, v.right);
    gl.uniform3fv(this.u.U, v.up);
    gl.uniform2f(this.u.tanHalf, t * (w / h), t);
    gl.uniform1i(this.u.tex, 0);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, this.tex);
    gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4);
  }
}

/// The orientation marks over the cut-out (issue 32: where am I, where do I look), drawn into a 2-D
/// canvas laid over it: the domain box's 12 edges, the horizon (directions level with the sky) and
/// ticks on it every 30° of heading (from north towards east = north × sky), north longer and yellow.
/// Straight lines stay straight in the cut-out (a perspective view): each edge is clipped to the space
/// in front of the viewer and drawn as one line. (In the fragment shader, the distance to 12 edges per
/// pixel cost ~50 ms a frame on software GL.)
/// scene: {basis: {right, up, forward}, position, sky, north, box: {lo, hi}} in world coordinates.
export function drawOrientationMarks(ctx, w, h, scene, look) {
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.clearRect(0, 0, w, h);
  if (!scene) return;
  const v = lookBasis(scene.basis, look);
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const t = Math.tan((look.fov * Math.PI) / 360), aspect = w / h, near = 1e-6;
  const view = (d) => [dot(d, v.right), dot(d, v.up), dot(d, v.forward)];
  const screen = (q) => [((q[0] / (q[2] * t * aspect)) + 1) * 0.5 * w, (1 - q[1] / (q[2] * t)) * 0.5 * h];
  /// A line between two view-space points, the part behind the viewer cut off.
  const line = (a, b) => {
    if (a[2] < near && b[2] < near) return;
    const cut = (p, q) => { const s = (near - p[2]) / (q[2] - p[2]); return p.map((x, i) => x + (q[i] - x) * s); };
    if (a[2] < near) a = cut(a, b);
    else if (b[2] < near) b = cut(b, a);
    const [x0, y0] = screen(a), [x1, y1] = screen(b);
    ctx.moveTo(x0, y0);
    ctx.lineTo(x1, y1);
  };
  const px = Math.max(1, h / 360);
  const rel = (p) => view(p.map((x, a) => x - scene.position[a]));
  const { lo, hi } = scene.box;
  ctx.lineCap = "round";
  ctx.strokeStyle = "rgba(235,235,235,0.75)";
  ctx.lineWidth = 1.6 * px;
  ctx.beginPath();
  for (let axis = 0; axis < 3; axis++)
    for (let k = 0; k < 4; k++) {
      const a = lo.slice(), u = (axis + 1) % 3, vv = (axis + 2) % 3;
      if (k & 1) a[u] = hi[u];
      if (k & 2) a[vv] = hi[vv];
      const b = a.slice();
      b[axis] = hi[axis];
      line(rel(a), rel(b));
    }
  ctx.stroke();
  // The horizon: the level directions, 72 chords of its circle.
  const sky = scene.sky, north = scene.north;
  const east = [north[1] * sky[2] - north[2] * sky[1], north[2] * sky[0] - north[0] * sky[2], north[0] * sky[1] - north[1] * sky[0]];
  const dirAt = (heading, elevation) => [0, 1, 2].map((i) => (north[i] * Math.cos(heading) + east[i] * Math.sin(heading)) * Math.cos(elevation) + sky[i] * Math.sin(elevation));
  ctx.strokeStyle = "rgba(115,205,255,0.6)";
  ctx.lineWidth = 1.4 * px;
  ctx.beginPath();
  for (let k = 0; k < 72; k++) line(view(dirAt((k * Math.PI) / 36, 0)), view(dirAt(((k + 1) * Math.PI) / 36, 0)));
  ctx.stroke();
  for (const isNorth of [false, true]) {
    ctx.strokeStyle = isNorth ? "rgba(255,215,50,0.95)" : "rgba(115,205,255,0.85)";
    ctx.lineWidth = 2 * px;
    ctx.beginPath();
    for (let k = 0; k < 12; k++) {
      if ((k === 0) !== isNorth) continue;
      const e = ((isNorth ? 3 : 1.5) * Math.PI) / 180 * (look.fov / 90);
      line(view(dirAt((k * Math.PI) / 6, -e)), view(dirAt((k * Math.PI) / 6, e)));
    }
    ctx.stroke();
  }
}
