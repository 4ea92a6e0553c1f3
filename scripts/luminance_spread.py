#!/usr/bin/python3
"""The foreground luminance spread of a rendered image (issue 17, item 6): the standard deviation
of the 8-bit Rec. 709 luma 0.2126 R + 0.7152 G + 0.0722 B over the pixels that are not the
background (the colour of the top-left pixel, a miss in every framed view).

    scripts/luminance_spread.py IMAGE.png [IMAGE.png ...]"""
import sys

import numpy
from PIL import Image


def spread(path):
    rgb = numpy.asarray(Image.open(path).convert("RGB"), dtype=numpy.float64)
    background = rgb[0, 0]
    foreground = numpy.any(rgb != background, axis=2)
    y = 0.2126 * rgb[..., 0] + 0.7152 * rgb[..., 1] + 0.0722 * rgb[..., 2]
    return float(y[foreground].std()), int(foreground.sum())


def main():
    for path in sys.argv[1:]:
        s, n = spread(path)
        print(f"{path}: luminance spread {s:.1f} over {n} foreground pixels")
    return 0 if len(sys.argv) > 1 else 2


if __name__ == "__main__":
    sys.exit(main())
