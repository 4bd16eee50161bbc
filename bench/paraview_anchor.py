# pvbatch script: ParaView 5.11's half of bench/paraview_bench.sh (issue 45): the anchor scene that
# build/bench/paraview_anchor wrote to DIR, volume-rendered by ParaView's CPU ray caster ("Ray Cast
# Only": vtkFixedPointVolumeRayCastMapper, one world unit = one voxel between samples, its default)
# from the same 8 cameras at the same size. Usage:
#   xvfb-run -s "-screen 0 1280x1024x24" pvbatch paraview_anchor.py DIR [ROUNDS [png]]
# Renders camera 0 once (warm-up: the mapper builds its gradients and encoded copy there), with
# "png" saves the 8 images as DIR/paraview_<i>.png, then times ROUNDS rounds (default 3) of the 8 cameras by
# this process's CPU time (all threads: user + system) around Render() alone (reading the pixels
# back for a PNG is left out, which favours ParaView). Prints "cpu_s_per_image X images N".
#
# Transfer function: panoptes' "p-wave" preset on |v| over [0, window] (window.txt, the 99.9th
# percentile of |p|): colour from (0.9, 0.35, 0.05) to (1, 0.8, 0.4); extinction 0 below 10 % of the
# window, then a linear ramp to 0.5 per voxel. ParaView has no |v|, so both signs get the same points
# (a table symmetric about 0), and its opacity is per unit distance: 1 - exp(-extinction) at the
# same points, ScalarOpacityUnitDistance 1 (one voxel), which is panoptes' opacity for a 1-voxel step.
import math
import os
import resource
import sys

from paraview.simple import *  # noqa: F401,F403

out = os.path.abspath(sys.argv[1])
rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 3
save_png = len(sys.argv) > 3 and sys.argv[3] == "png"
NX, NY, NZ = 128, 256, 80
W, H = 920, 896
ref = float(open(os.path.join(out, "window.txt")).read())

reader = ImageReader(FileNames=[os.path.join(out, "field.raw")])
reader.DataScalarType = "float"
reader.DataByteOrder = "LittleEndian"
reader.DataExtent = [0, NX - 1, 0, NY - 1, 0, NZ - 1]
reader.DataSpacing = [1, 1, 1]
reader.DataOrigin = [0, 0, 0]
reader.UpdatePipeline()

view = CreateView("RenderView")
view.ViewSize = [W, H]
view.OrientationAxesVisibility = 0
view.Background = [0, 0, 0]
try:  # 5.11: the background is the view's own colour only when UseColorPaletteForBackground is off
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass
disp = Show(reader, view)
disp.SetRepresentationType("Volume")
disp.VolumeRenderingMode = "Ray Cast Only"
disp.ColorArrayName = ["POINTS", "ImageFile"]
disp.ScalarOpacityUnitDistance = 1.0
disp.Shade = 0

lut = GetColorTransferFunction("ImageFile")
pwf = GetOpacityTransferFunction("ImageFile")
c0, c1 = (0.9, 0.35, 0.05), (1.0, 0.8, 0.4)
us = [i / 20 for i in range(21)]  # |v| / window
rgb, pts = [], []
for u in us:
    c = [a + (b - a) * u for a, b in zip(c0, c1)]
    tau = 0.0 if u <= 0.1 else 0.5 * (u - 0.1) / 0.9
    alpha = 1.0 - math.exp(-tau)
    for v in ([-u * ref, u * ref] if u > 0 else [0.0]):
        rgb.append((v, c))
        pts.append((v, alpha))
rgb.sort()
pts.sort()
lut.RGBPoints = [x for v, c in rgb for x in (v, *c)]
lut.ColorSpace = "RGB"
pwf.Points = [x for v, a in pts for x in (v, a, 0.5, 0.0)]
lut.AutomaticRescaleRangeMode = "Never"
pwf.AllowDuplicateScalars = 1

cx, cy, cz = (NX - 1) / 2, (NY - 1) / 2, (NZ - 1) / 2
diag = math.sqrt((NX - 1) ** 2 + (NY - 1) ** 2 + (NZ - 1) ** 2)


def place(i):
    d = [1.0 if i & 1 else -1.0, 1.0 if i & 2 else -1.0, 0.6 if i & 4 else -0.6]
    n = math.sqrt(sum(x * x for x in d))
    cam = view.GetActiveCamera()
    cam.SetFocalPoint(cx, cy, cz)
    cam.SetPosition(*[c + x / n * 1.1 * diag for c, x in zip((cx, cy, cz), d)])
    cam.SetViewUp(0, 0, 1)
    cam.SetViewAngle(30)
    view.CenterOfRotation = [cx, cy, cz]
    view.GetRenderer().ResetCameraClippingRange()


def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


place(0)
Render(view)  # warm-up
for i in range(8 if save_png else 0):
    place(i)
    Render(view)
    SaveScreenshot(os.path.join(out, "paraview_%d.png" % i), view, ImageResolution=[W, H])
t0 = cpu()
for _ in range(rounds):
    for i in range(8):
        place(i)
        Render(view)
print("cpu_s_per_image %.5f images %d" % ((cpu() - t0) / (8 * rounds), 8 * rounds), flush=True)
