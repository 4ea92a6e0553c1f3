"""The octiso Python module against independent references: numpy round trips for all 8 dtypes,
renders equal to octiso-render's image bit for bit, zero-copy builds, GIL release, and refusals.
Run by ctest (tests/python/CMakeLists.txt passes the build tree's package and tools)."""
import os
import subprocess
import tempfile
import threading
import time

import numpy as np
import pytest

import octiso

TOOLS = os.environ.get("OCTISO_TOOLS_DIR", "")
DTYPES = [np.uint8, np.int8, np.uint16, np.int16, np.uint32, np.int32, np.float32, np.float64]
SHAPES = [(1, 1, 1), (2, 2, 2), (5, 3, 7), (17, 33, 65), (1, 1, 1000)]


def field(shape, dtype, seed=1):
    """Smooth data plus noise in [0, 120], so that every dtype holds it and little merges."""
    z, y, x = np.meshgrid(*[np.linspace(-1, 1, n) for n in shape], indexing="ij")
    f = 60 + 50 * np.cos(3 * x) * np.sin(2 * y + z) + np.random.default_rng(seed).uniform(-10, 10, shape)
    if np.issubdtype(dtype, np.integer):
        f = np.round(f)
    return f.astype(dtype)


@pytest.mark.parametrize("dtype", DTYPES)
@pytest.mark.parametrize("shape", SHAPES)
def test_round_trip_is_exact(dtype, shape):
    a = field(shape, dtype)
    tree = octiso.build(a)
    assert tree.dtype == np.dtype(dtype)
    assert tree.shape == shape
    assert tree.dims == (shape[2], shape[1], shape[0])
    b = tree.to_numpy()
    assert b.dtype == a.dtype and b.shape == a.shape
    assert np.array_equal(a, b)


@pytest.mark.parametrize("dtype", [np.dtype(">u2"), np.dtype(">f4"), np.dtype("<i4")])
def test_foreign_byte_order_is_read_as_values(dtype):
    a = field((9, 8, 7), np.float64).astype(dtype)
    assert np.array_equal(octiso.build(a).to_numpy(), a.astype(dtype.newbyteorder("=")))


def test_placement_and_info():
    a = field((12, 10, 8), np.uint8)
    tree = octiso.build(a, spacing=(0.5, 1.0, 2.0), origin=(-3, 4, 5))
    info = tree.info()
    assert info["type"] == "u8"
    assert info["dims"] == (8, 10, 12) and info["shape"] == (12, 10, 8)
    assert info["spacing"] == (0.5, 1.0, 2.0) and info["origin"] == (-3.0, 4.0, 5.0)
    lo, hi = info["value_range"]
    assert lo == a.min() and hi == a.max()
    assert info["dense_bytes"] == a.nbytes


def test_save_open_and_steps(tmp_path):
    a = field((20, 21, 22), np.int16)
    tree = octiso.build(a, spacing=(1, 2, 3))
    path = str(tmp_path / "t.oct")
    tree.save(path)
    f = octiso.open(path)
    assert f.steps == 1 and len(f) == 1
    back = f.step(0)
    assert back.spacing == (1.0, 2.0, 3.0)
    assert np.array_equal(back.to_numpy(), a)
    assert f.info()["steps"] == 1


def read_png(path):
    """PNG -> uint8 array through matplotlib (Debian's python3-matplotlib), independent of octiso."""
    import matplotlib.image
    img = matplotlib.image.imread(path)
    if img.dtype != np.uint8:
        img = np.round(img * 255).astype(np.uint8)
    return img[:, :, :3]


def test_render_equals_the_tool(tmp_path):
    if not TOOLS:
        pytest.fail("OCTISO_TOOLS_DIR must name the build directory with octiso-render")
    a = field((40, 36, 44), np.float32)
    path = str(tmp_path / "v.oct")
    octiso.build(a).save(path)
    png = str(tmp_path / "tool.png")
    # The Renderer's own colour is the tool's --shading headlight (the tool's default is the light kit).
    cmd = [os.path.join(TOOLS, "octiso-render"), path, "--iso", "60.5", "--size", "96x72", "-o", png,
           "--eye", "60,-40,50", "--look", "21,17,19", "--up", "0,0,1", "--fov", "45", "--shading", "headlight"]
    subprocess.run(cmd, check=True, capture_output=True)
    tree = octiso.open(path).step(0)
    camera = octiso.Camera(eye=(60, -40, 50), look=(21, 17, 19), up=(0, 0, 1), fov=45)
    frame = tree.render(60.5, camera=camera, size=(96, 72))
    assert frame.rgb.shape == (72, 96, 3) and frame.rgb.dtype == np.uint8
    assert frame.hits > 1000
    assert np.array_equal(frame.rgb, read_png(png))
    # The default framing is the tool's default framing too.
    subprocess.run([os.path.join(TOOLS, "octiso-render"), path, "--iso", "60.5", "--size", "64x48", "-o", png,
                    "--shading", "headlight"],
                   check=True, capture_output=True)
    assert np.array_equal(tree.render(60.5, size=(64, 48)).rgb, read_png(png))


def test_renderer_keeps_scene_and_matches_one_call_renders():
    tree = octiso.build(field((30, 31, 32), np.uint16))
    r = octiso.Renderer(tree, 50, size=(64, 64), depth=True, normal=True)
    for iso in (40, 55.5, 70):
        r.iso = iso
        for az in (0, 120):
            cam = octiso.Camera.frame(tree, azimuth=az, elevation=20, size=(64, 64))
            a = r.render(cam)
            b = tree.render(iso, camera=cam, size=(64, 64), depth=True, normal=True)
            assert a.hits > 0
            assert np.array_equal(a.rgb, b.rgb)
            assert np.array_equal(a.depth, b.depth)
            assert np.array_equal(a.normal, b.normal)
    assert a.depth.dtype == np.float32 and a.depth.shape == (64, 64)
    assert a.normal.shape == (64, 64, 3)
    assert np.isinf(a.depth).any() and np.isfinite(a.depth).any()


def test_level_of_detail_matches_the_tool_and_changes_only_far_views():
    tree = octiso.build(field((40, 36, 44), np.uint8))
    exact = tree.render(47, size=(128, 128), depth=True)
    # Close (under one voxel per pixel) any factor up to 1 is the exact frame.
    assert np.array_equal(tree.render(47, size=(128, 128), depth=True, lod=1.0).depth, exact.depth)
    r = octiso.Renderer(tree, 47, size=(128, 128), depth=True, lod=16.0)
    coarse = r.render()
    assert coarse.hits > 0
    assert not np.array_equal(coarse.depth, exact.depth)
    assert np.array_equal(coarse.depth, tree.render(47, size=(128, 128), depth=True, lod=16.0).depth)


def test_frame_arrays_own_their_memory():
    tree = octiso.build(field((16, 16, 16), np.uint8))
    frame = tree.render(60, size=(32, 32))
    rgb = frame.rgb
    assert rgb.flags["OWNDATA"] is False and rgb.base is not None   # adopted, not copied
    del frame, tree
    assert rgb.sum() > 0   # still valid after the frame and tree are gone


def test_build_reads_the_array_in_place():
    """A 256 MiB array builds without a second copy of the voxels: peak RSS grows by far less."""
    import resource
    a = np.full((512, 512, 1024), 3, dtype=np.uint8)       # every page written: resident now
    a[200:300, 200:300, 200:700] = 7                        # a little structure, the rest merges
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    tree = octiso.build(a)
    after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    assert tree.info()["bytes"] < a.nbytes // 16
    assert after - before < a.nbytes // 4, (before, after)


def test_gil_is_released_while_rendering():
    tree = octiso.build(field((64, 64, 64), np.float32))
    r = octiso.Renderer(tree, 60, size=(400, 400), threads=1)
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(1)
            time.sleep(0.0005)

    t = threading.Thread(target=count)
    t.start()
    frames = 0
    start = time.perf_counter()
    while time.perf_counter() - start < 0.5:
        r.render()
        frames += 1
    done.set()
    t.join()
    # Had render() held the GIL, the counter could only run between frames (a few ticks).
    assert len(ticks) > 4 * frames, (len(ticks), frames)


@pytest.mark.parametrize("bad, error", [
    (np.zeros((4, 4), np.uint8), ValueError),                   # not 3-D
    (np.zeros((4, 4, 4, 1), np.uint8), ValueError),
    (np.zeros((4, 4, 8), np.uint8)[:, :, ::2], ValueError),     # not contiguous
    (np.zeros((4, 4, 4), np.bool_), TypeError),
    (np.zeros((4, 4, 4), np.int64), TypeError),
    (np.zeros((4, 4, 4), np.complex64), TypeError),
    (np.zeros((0, 4, 4), np.uint8), ValueError),
])
def test_bad_arrays_raise(bad, error):
    with pytest.raises(error):
        octiso.build(bad)


def test_bad_arguments_raise_with_the_tools_messages(tmp_path):
    tree = octiso.build(field((8, 8, 8), np.uint8))
    with pytest.raises(ValueError):
        octiso.build(np.zeros((4, 4, 4), np.uint8), spacing=(1, 0, 1))
    with pytest.raises(ValueError):
        octiso.build(np.zeros((4, 4, 4), np.uint8), spacing=(1, 1))
    with pytest.raises(ValueError, match="--iso"):
        tree.render([])
    with pytest.raises(ValueError, match="--iso"):
        tree.render(list(range(9)))
    with pytest.raises(ValueError, match="--root-finder"):
        tree.render(50, root_finder="newton")
    with pytest.raises(ValueError, match="size"):
        tree.render(50, size=(0, 10))
    with pytest.raises(ValueError, match="--lod"):
        tree.render(50, lod=-1)
    with pytest.raises(ValueError, match="--look"):
        octiso.Camera(eye=(1, 2, 3), look=(1, 2, 3))
    with pytest.raises(ValueError, match="--elevation"):
        octiso.Camera.frame(tree, elevation=95)
    missing = str(tmp_path / "missing.oct")
    with pytest.raises(OSError, match="missing.oct"):
        octiso.open(missing)
    junk = tmp_path / "junk.oct"
    junk.write_bytes(b"not an octree" * 10)
    with pytest.raises(OSError, match="junk.oct"):
        octiso.open(str(junk))
    ranged = octiso.build(field((8, 8, 8), np.uint8), iso_range=(20, 90))
    with pytest.raises(ValueError, match="iso-range"):
        ranged.render(95)


def test_convert_matches_the_tool_byte_for_byte(tmp_path):
    a = field((11, 13, 17), np.uint16)
    raw = tmp_path / "v.raw"
    a.tofile(raw)
    mine, theirs = str(tmp_path / "py.oct"), str(tmp_path / "tool.oct")
    report = octiso.convert(str(raw), mine, dims=(17, 13, 11), dtype="u16", spacing=(1, 2, 3))
    assert report["steps"] == 1 and report["dims"] == (17, 13, 11) and report["file_bytes"] > 0
    subprocess.run([os.path.join(TOOLS, "octiso-convert"), str(raw), "--dims", "17,13,11", "--type", "u16",
                    "--spacing", "1,2,3", "-o", theirs], check=True, capture_output=True)
    assert open(mine, "rb").read() == open(theirs, "rb").read()
    assert np.array_equal(octiso.open(mine).step(0).to_numpy(), a)
    with pytest.raises(ValueError, match="same file as the input"):   # never onto its input (subject: -o)
        octiso.convert(str(raw), str(raw), dims=(17, 13, 11), dtype="uint16")
    with pytest.raises(ValueError):
        octiso.convert(str(raw), mine, dims=(17, 13, 11), dtype="u16", endian="middle")


def write_scaled_nifti(path, volume, slope, inter):
    """A NIfTI-1 file (header by the standard's byte offsets, as tests/io/nifti_test_file.h writes
    it) of an int16 [z, y, x] array with scl_slope/scl_inter, independent of octiso's reader."""
    import struct
    nz, ny, nx = volume.shape
    h = bytearray(352)
    struct.pack_into("<i", h, 0, 348)
    struct.pack_into("<8h", h, 40, 3, nx, ny, nz, 1, 1, 1, 1)
    struct.pack_into("<hh", h, 70, 4, 16)                      # datatype int16, bitpix
    struct.pack_into("<8f", h, 76, 1, 1, 1, 1, 1, 1, 1, 1)     # pixdim (qfac 1)
    struct.pack_into("<fff", h, 108, 352.0, slope, inter)      # vox_offset, scl_slope, scl_inter
    h[344:348] = b"n+1\0"
    with open(path, "wb") as f:
        f.write(bytes(h) + volume.astype("<i2").tobytes())


def test_isovalues_and_ranges_are_real_values_of_a_scaled_nifti(tmp_path):
    """CONVENTIONS 2b: real = stored * slope + inter. render() and Renderer take real isovalues and
    draw what octiso-render draws for the same --iso; info() reports the real ranges."""
    if not TOOLS:
        pytest.fail("OCTISO_TOOLS_DIR must name the build directory with octiso-render")
    a = np.round(field((30, 28, 26), np.float32)).astype(np.int16)
    nii, path = str(tmp_path / "s.nii"), str(tmp_path / "s.oct")
    write_scaled_nifti(nii, a, 0.5, -10)
    octiso.convert(nii, path)
    tree = octiso.open(path).step(0)
    info = tree.info()
    assert info["value_scale"] == (0.5, -10.0)
    assert np.array_equal(tree.to_numpy(), a)                  # the tree keeps the stored values
    lo, hi = info["value_range"]
    assert (lo, hi) == (0.5 * int(a.min()) - 10, 0.5 * int(a.max()) - 10)
    real_iso, stored_iso = 20.25, 60.5                        # 60.5 * 0.5 - 10
    png = str(tmp_path / "tool.png")
    subprocess.run([os.path.join(TOOLS, "octiso-render"), path, "--iso", str(real_iso), "--size", "64x48", "-o", png,
                    "--shading", "headlight"], check=True, capture_output=True)
    frame = tree.render(real_iso, size=(64, 48))
    assert frame.hits > 300
    assert np.array_equal(frame.rgb, read_png(png))
    # The same surface as the stored isovalue in an unscaled tree of the same voxels.
    assert np.array_equal(frame.rgb, octiso.build(a).render(stored_iso, size=(64, 48)).rgb)
    r = octiso.Renderer(tree, 0.0, size=(64, 48))
    r.iso = real_iso
    assert r.iso == [real_iso]
    assert np.array_equal(r.render().rgb, frame.rgb)
    # An iso-range given in real values is checked and named in real values.
    ranged = str(tmp_path / "r.oct")
    octiso.convert(nii, ranged, iso_range=(0, 30))
    rt = octiso.open(ranged).step(0)
    assert rt.info()["iso_range"] == (0.0, 30.0)
    assert rt.render(real_iso, size=(8, 8)).rays == 64
    with pytest.raises(ValueError, match=r"outside the iso-range \(0\.000000, 30\.000000\)"):
        rt.render(31, size=(8, 8))
