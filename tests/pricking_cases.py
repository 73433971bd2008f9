"""The spec's example loops, mirrored into this project's frame (x = forward travel)."""

import numpy as np

SPEC_KERNEL_A = [(-120, -135), (-110, -180), (-80, -215), (-45, -255), (5, -288), (60, -262),
                 (95, -215), (125, -160), (125, -110), (85, -78), (10, -70), (-75, -92)]
SPEC_KERNEL_B = [(-112.6, -139.3), (-105.5, -187.5), (-82.6, -223.4), (-41.9, -265.5),
                 (8.6, -290.1), (57.3, -272.6), (100.7, -223.4), (129.1, -169.0),
                 (128.0, -117.4), (85.8, -87.3), (14.0, -79.0), (-72.7, -98.4)]


def mirrored(points):
    points = np.array(points, dtype=float)
    points[:, 0] *= -1.0
    return points


KERNEL_A = mirrored(SPEC_KERNEL_A)
KERNEL_B = mirrored(SPEC_KERNEL_B)
