# Writes scenes/mitsuba/sky.exr: a procedural 64 x 32 latitude-longitude sky (a blue zenith
# fading to a pale horizon, a warm sun 30 degrees up, a green-brown ground).
import math, sys
import numpy as np
import mitsuba as mi
mi.set_variant('scalar_rgb')
W, H = 64, 32
img = np.zeros((H, W, 3), dtype=np.float32)
sun = np.array([math.sin(1.0) * math.cos(math.radians(30)), math.sin(math.radians(30)), -math.cos(1.0) * math.cos(math.radians(30))])
for y in range(H):
    theta = math.pi * y / (H - 1)
    for x in range(W):
        phi = 2 * math.pi * (x + 0.5) / W
        d = np.array([math.sin(phi) * math.sin(theta), math.cos(theta), -math.cos(phi) * math.sin(theta)])
        if d[1] >= 0:
            t = d[1]
            c = np.array([0.9, 0.95, 1.0]) * (1 - t) + np.array([0.25, 0.45, 0.9]) * t
        else:
            c = np.array([0.25, 0.3, 0.12])
        s = max(0.0, float(d @ sun))
        c = c + np.array([30.0, 24.0, 15.0]) * s ** 200
        img[y, x] = c
mi.Bitmap(img).write(sys.argv[1])
