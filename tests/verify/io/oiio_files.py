#!/usr/bin/env python3
"""Debian's OpenImageIO as the independent side of tests/verify/io (issue 23).

  oiio_files.py write DIR      OpenImageIO writes EXR (RGB, XYZ, windowed, hand-named spectral), .hdr and .pfm files
                               into DIR; the values it was given go beside each as NAME.truth.f32 (float32, top row
                               first, channels interleaved) and DIR/truth.json lists width, height and channel names.
  oiio_files.py read FILE...   OpenImageIO reads each file; its pixels go to FILE.oiio.f32 and its channel names and
                               attributes to one JSON document on stdout.
"""
import json
import sys

import numpy as np
import OpenImageIO as oiio


def values(rng, h, w, c):
    # Positive radiance-like values over ten stops, plus exact zeros (a renderer's black).
    v = np.exp(rng.uniform(-5.0, 5.0, size=(h, w, c))).astype(np.float32)
    v[0, 0, :] = 0.0
    return v


def write(path, spec, data):
    out = oiio.ImageOutput.create(path)
    if out is None or not out.open(path, spec):
        raise SystemExit("OpenImageIO cannot write %s: %s" % (path, oiio.geterror()))
    if not out.write_image(data):
        raise SystemExit("OpenImageIO write_image failed for %s: %s" % (path, out.geterror()))
    out.close()


def cmd_write(d):
    rng = np.random.default_rng(20230)
    truth = {}

    def emit(name, spec, data, full=None, names=None):
        write(d + "/" + name, spec, data)
        t = data if full is None else full
        np.ascontiguousarray(t, dtype="<f4").tofile(d + "/" + name + ".truth.f32")
        truth[name] = {"width": int(t.shape[1]), "height": int(t.shape[0]),
                       "channels": names or list(spec.channelnames)}

    h, w = 37, 53  # odd sizes: no row or tile boundary lines up by chance
    # RGB with Display P3 chromaticities and a white luminance: both attributes must reach the reader.
    spec = oiio.ImageSpec(w, h, 3, "float")
    spec.channelnames = ("R", "G", "B")
    spec.attribute("chromaticities", oiio.TypeDesc("float[8]"),
                   (0.680, 0.320, 0.265, 0.690, 0.150, 0.060, 0.3127, 0.3290))
    spec.attribute("whiteLuminance", 250.0)
    spec.attribute("compression", "zip")
    emit("rgb.exr", spec, values(rng, h, w, 3))

    spec = oiio.ImageSpec(w, h, 3, "half")  # half channels are converted to float by the reader
    spec.channelnames = ("R", "G", "B")
    spec.attribute("compression", "piz")
    data = values(rng, h, w, 3).astype(np.float16).astype(np.float32)
    emit("rgb_half.exr", spec, data)

    spec = oiio.ImageSpec(w, h, 3, "float")  # tiled, 16 x 16 tiles: the edge tiles are partial
    spec.channelnames = ("R", "G", "B")
    spec.tile_width, spec.tile_height = 16, 16
    emit("rgb_tiled.exr", spec, values(rng, h, w, 3))

    spec = oiio.ImageSpec(w, h, 3, "float")
    spec.channelnames = ("X", "Y", "Z")
    spec.attribute("compression", "none")
    emit("xyz.exr", spec, values(rng, h, w, 3))

    # Data window (2,1)-(5,3) inside an 8 x 6 display window: the pixels outside are OpenEXR's zero.
    spec = oiio.ImageSpec(4, 3, 3, "float")
    spec.channelnames = ("R", "G", "B")
    spec.x, spec.y = 2, 1
    spec.full_x, spec.full_y, spec.full_width, spec.full_height = 0, 0, 8, 6
    block = values(rng, 3, 4, 3)
    full = np.zeros((6, 8, 3), np.float32)
    full[1:4, 2:6, :] = block
    emit("window.exr", spec, block, full=full)

    # A spectral file named by hand in the JCGT layout's other spellings: micrometres, plain integers, an
    # exponent, terahertz; R,G,B preview channels beside them (ignored by the spectral reader).
    bands = [("S0.400nm", 400.0), ("S0.0,45um", 450.0), ("S0.5,5E2nm", 550.0), ("S0.500,000000nm", 500.0),
             ("S0.499,654096THz", 299792458.0 / 499.654096e12 * 1e9)]
    names = [b[0] for b in bands] + ["R", "G", "B"]
    spec = oiio.ImageSpec(w, h, len(names), "float")
    spec.channelnames = tuple(names)
    spec.attribute("spectralLayoutVersion", "1.0")
    spec.attribute("emissiveUnits", "W.m^-2.sr^-1")
    data = values(rng, h, w, len(names))
    write(d + "/spectral_hand.exr", spec, data)
    order = sorted(range(len(bands)), key=lambda i: bands[i][1])
    np.ascontiguousarray(data[:, :, order], dtype="<f4").tofile(d + "/spectral_hand.exr.truth.f32")
    truth["spectral_hand.exr"] = {"width": w, "height": h, "channels": [bands[i][0] for i in order],
                                  "wavelengths_nm": [bands[i][1] for i in order]}

    spec = oiio.ImageSpec(w, h, 3, "float")
    emit("rgb.hdr", spec, values(rng, h, w, 3))

    # Debian's OpenImageIO 2.4 reads PFM but has no PFM writer: these are written here from the format's
    # definition (rows bottom-up, scale sign = byte order) and OpenImageIO's reading of them is the other truth.
    def pfm(name, data, little):
        kind = b"PF" if data.shape[2] == 3 else b"Pf"
        body = np.ascontiguousarray(data[::-1], dtype=("<f4" if little else ">f4")).tobytes()
        with open(d + "/" + name, "wb") as f:
            f.write(kind + b"\n%d %d\n%s\n" % (data.shape[1], data.shape[0], b"-1.0" if little else b"1.0") + body)
        rgb = data if data.shape[2] == 3 else np.repeat(data, 3, axis=2)
        np.ascontiguousarray(rgb, dtype="<f4").tofile(d + "/" + name + ".truth.f32")
        truth[name] = {"width": w, "height": h, "channels": ["R", "G", "B"]}

    pfm("rgb_le.pfm", values(rng, h, w, 3), True)
    pfm("rgb_be.pfm", values(rng, h, w, 3), False)
    pfm("grey.pfm", values(rng, h, w, 1), True)
    with open(d + "/truth.json", "w") as f:
        json.dump(truth, f, indent=1)


def cmd_read(files):
    report = {}
    for path in files:
        inp = oiio.ImageInput.open(path)
        if inp is None:
            raise SystemExit("OpenImageIO cannot open %s: %s" % (path, oiio.geterror()))
        spec = inp.spec()
        data = inp.read_image("float")
        inp.close()
        np.ascontiguousarray(data, dtype="<f4").tofile(path + ".oiio.f32")
        attrs = {}
        for name in ("chromaticities", "whiteLuminance", "spectralLayoutVersion", "emissiveUnits"):
            v = spec.getattribute(name)
            if v is not None:
                attrs[name] = list(v) if isinstance(v, tuple) else v
        report[path] = {"width": spec.width, "height": spec.height, "channels": list(spec.channelnames),
                        "attributes": attrs}
    json.dump(report, sys.stdout)


if __name__ == "__main__":
    if len(sys.argv) >= 3 and sys.argv[1] == "write":
        cmd_write(sys.argv[2])
    elif len(sys.argv) >= 3 and sys.argv[1] == "read":
        cmd_read(sys.argv[2:])
    else:
        raise SystemExit(__doc__)
