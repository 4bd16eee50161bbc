// The perspective cut-out of an equirectangular (360° × 180°) frame, drawn by WebGL2: the decoded
// VideoFrame is the texture and a fragment shader maps every pixel's ray to longitude/latitude — the
// same mapping as the desktop's look mesh (src/ui/look_mesh.cpp) and its CPU reference
// player::perspective_cutout (longitude wraps, bilinear sampling, latitude clamped at the poles).

const VERTEX = `#version 300 es
in vec2 p;
out vec2 ndc;
void main() { ndc = p; gl_Position = vec4(p, 0.0, 1.0); }`;

// Directions are in the camera's own frame: x = right, y = up, z = forward. The orientation marks
// (issue 32: "where am I, where do I look") are drawn over the frame in world terms: the domain box's
// 12 edges as the curves they are in the cut-out, the horizon (directions level with the sky), and
// ticks on it every 30° of heading (from north towards east = north × sky), the north one longer and
// yellow.
const FRAGMENT = `#version 300 es
precision highp float;
in vec2 ndc;
uniform vec3 F, R, U;
uniform vec2 tanHalf;
uniform sampler2D tex;
uniform bool marks;
uniform vec3 camRight, camUp, camForward, camPos, sky, north, boxLo, boxHi;
uniform float pixelAngle;  // radians per drawn pixel at the centre
out vec4 colour;
const float PI = 3.14159265358979;
// Angle (radians) between the ray from the camera along unit w and the segment a-b, or 10 when the
// closest approach lies behind the camera.
float segmentAngle(vec3 w, vec3 a, vec3 b) {
  vec3 e = b - a, o = camPos - a;
  float ee = dot(e, e), we = dot(w, e), wo = dot(w, o), eo = dot(e, o);
  float den = ee - we * we;
  float s = den > 1e-12 * ee ? clamp((eo - we * wo) / den, 0.0, 1.0) : 0.0;  // along the segment
  vec3 q = a + e * s - camPos;
  float t = dot(q, w);
  if (t <= 0.0) return 10.0;
  return length(q - w * t) / t;
}
void main() {
  vec3 d = F + R * (ndc.x * tanHalf.x) + U * (ndc.y * tanHalf.y);
  float lon = atan(d.x, d.z), lat = atan(d.y, length(d.xz));
  vec3 c = texture(tex, vec2((lon / PI + 1.0) * 0.5, 0.5 - lat / PI)).rgb;
  if (marks) {
    vec3 w = normalize(camRight * d.x + camUp * d.y + camForward * d.z);
    float px = pixelAngle * length(d) / length(F);  // a pixel's angle grows off-centre
    // Box edges: 4 along each axis.
    float edge = 10.0;
    for (int axis = 0; axis < 3; ++axis)
      for (int k = 0; k < 4; ++k) {
        vec3 a = boxLo, b;
        int u = (axis + 1) % 3, v = (axis + 2) % 3;
        if ((k & 1) == 1) a[u] = boxHi[u];
        if ((k & 2) == 2) a[v] = boxHi[v];
        b = a;
        b[axis] = boxHi[axis];
        edge = min(edge, segmentAngle(w, a, b));
      }
    c = mix(c, vec3(0.92), 0.75 * (1.0 - smoothstep(0.6, 1.4, edge / px)));
    // Horizon and heading ticks (heading from north towards east = north x sky).
    float h = asin(clamp(dot(w, sky), -1.0, 1.0));
    c = mix(c, vec3(0.45, 0.8, 1.0), 0.5 * (1.0 - smoothstep(0.5, 1.2, abs(h) / px)));
    vec3 level = w - sky * dot(w, sky);
    float levelLen = length(level);
    if (levelLen > 1e-4) {
      level /= levelLen;
      float heading = atan(dot(level, cross(north, sky)), dot(level, north));
      float tick = radians(30.0), nearest = tick * floor(heading / tick + 0.5);
      float off = abs(heading - nearest) * levelLen;
      bool isNorth = abs(nearest) < 0.01;
      float len = (isNorth ? 14.0 : 7.0) * px;
      if (off < 1.2 * px && abs(h) < len) c = mix(c, isNorth ? vec3(1.0, 0.85, 0.2) : vec3(0.45, 0.8, 1.0), 0.85);
    }
  }
  colour = vec4(c, 1.0);
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
    this.u = Object.fromEntries(["F", "R", "U", "tanHalf", "tex", "marks", "camRight", "camUp", "camForward", "camPos", "sky", "north",
                                 "boxLo", "boxHi", "pixelAngle"].map((n) => [n, gl.getUniformLocation(prog, n)]));
    this.scene = null;
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

  /// The world around the camera for the orientation marks, or null for none: {basis: {right, up,
  /// forward}, position, sky, north, box: {lo, hi}} (world coordinates).
  setScene(scene) {
    this.scene = scene;
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
    const sc = this.scene;
    gl.uniform1i(this.u.marks, sc ? 1 : 0);
    if (sc) {
      gl.uniform3fv(this.u.camRight, sc.basis.right);
      gl.uniform3fv(this.u.camUp, sc.basis.up);
      gl.uniform3fv(this.u.camForward, sc.basis.forward);
      // Relative to the camera: float32 positions of a 50 km domain would lose the metres.
      gl.uniform3fv(this.u.camPos, [0, 0, 0]);
      gl.uniform3fv(this.u.boxLo, sc.box.lo.map((x, a) => x - sc.position[a]));
      gl.uniform3fv(this.u.boxHi, sc.box.hi.map((x, a) => x - sc.position[a]));
      gl.uniform3fv(this.u.sky, sc.sky);
      gl.uniform3fv(this.u.north, sc.north);
      gl.uniform1f(this.u.pixelAngle, (2 * t) / h);
    }
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, this.tex);
    gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4);
  }
}
