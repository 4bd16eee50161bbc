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

/// The unit frame of a camera looking along +z with +y up, in its own coordinates.
const CAMERA_FRAME = { forward: [0, 0, 1], right: [1, 0, 0], up: [0, 1, 0] };

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
    const v = lookBasis(CAMERA_FRAME, look);
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
