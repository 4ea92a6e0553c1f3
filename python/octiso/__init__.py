"""octiso: exact isosurfaces of losslessly compressed octree volumes, ray traced on all cores.

numpy in, images out::

    import numpy, octiso
    tree = octiso.build(volume)                      # a [z, y, x] array, read in place
    frame = tree.render(100.5, size=(512, 512))      # frame.rgb: uint8 (512, 512, 3)
    r = octiso.Renderer(tree, 100.5)                 # keeps its scene between frames
    for az in range(0, 360, 30):
        image = r.render(octiso.Camera.frame(tree, azimuth=az)).rgb

Isovalues and the ranges of Tree.info() are real values, as the tools take and report them:
for a NIfTI with scl_slope/scl_inter, real = stored * slope + inter (info()['value_scale']).

Errors carry the command-line tools' one-line messages: ValueError for bad arguments, OSError
for files, TypeError for arrays of a type octiso does not store.
"""
from ._octiso import Camera, File, Frame, Renderer, Tree, __version__, build, convert, open  # noqa: A004

__all__ = ["Camera", "File", "Frame", "Renderer", "Tree", "build", "convert", "open", "__version__"]
