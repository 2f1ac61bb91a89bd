#!/usr/bin/env python3
"""Reference FLIP values for tests/test_compare.c, from NVIDIA's flip-evaluator.

The test builds small procedural image pairs (gradients, a checkerboard,
noise from a fixed-seed PCG32, a blurred, a shifted and a colour-shifted
copy, constants) with integer arithmetic, so this script and the C test make
bit-identical float images; each image's FNV-1a hash is printed so the test
can check that. For every pair it prints LDR-FLIP (the images taken as sRGB
values in [0, 1]) and HDR-FLIP (the same images scaled by a power of two
that grows across the width, as linear radiance) as the C table the test
holds, and writes the images as PFM files to --out for `rt compare`.

    python3 -m venv /tmp/flip && /tmp/flip/bin/pip install flip-evaluator==1.7 numpy
    /tmp/flip/bin/python tools/flip_reference.py            # the table in tests/test_compare.c
    /tmp/flip/bin/python tools/flip_reference.py CAND.pfm REF.pfm   # any two PFM images
    /tmp/flip/bin/python tools/flip_reference.py --big   # test_flip_512_time's 512x512 LDR-FLIP

With two PFM files (linear RGB, as rt writes them) it prints LDR-FLIP of the
images clamped to [0, 1] and sRGB-encoded, and HDR-FLIP of the linear
values: the numbers `rt compare CAND.pfm REF.pfm` should print. (Of the
pairs written to --out, `rt compare NAME-cand-hdr.pfm NAME-ref-hdr.pfm`
prints the table's HDR-FLIP; the -ldr files hold the sRGB values themselves,
which rt compare, taking them as linear, would encode once more.)
"""
import argparse
import os
import sys

import numpy as np

W, H = 96, 64
ONE = 65536  # image values are integers q, the float value is q / 65536 (exact)


def pcg32(seed, seq):
    """PCG32 (O'Neill, pcg-random.org: pcg32_srandom_r / pcg32_random_r)."""
    mask = (1 << 64) - 1
    inc = ((seq << 1) | 1) & mask
    state = 0

    def step(s):
        return (s * 6364136223846793005 + inc) & mask

    state = step(state)
    state = (state + seed) & mask
    state = step(state)
    while True:
        old = state
        state = step(state)
        xorshifted = (((old >> 18) ^ old) >> 27) & 0xFFFFFFFF
        rot = old >> 59
        yield ((xorshifted >> rot) | (xorshifted << ((-rot) & 31))) & 0xFFFFFFFF


def base():
    """The reference: a colour gradient averaged with an 8-pixel checkerboard."""
    q = np.zeros((H, W, 3), dtype=np.int64)
    for y in range(H):
        for x in range(W):
            grad = [(x * 4095) // (W - 1), (y * 4095) // (H - 1), ((x + y) * 4095) // (W + H - 2)]
            c = 3300 if ((x // 8 + y // 8) & 1) else 700
            check = [c, (c * 3) // 4, c // 2]
            for k in range(3):
                q[y, x, k] = 16 * ((grad[k] + check[k]) // 2)
    return q


def noisy(q):
    rng = pcg32(42, 54)
    out = q.copy()
    for y in range(H):
        for x in range(W):
            for k in range(3):
                out[y, x, k] = min(max(q[y, x, k] + (next(rng) >> 19) - 4096, 0), ONE)
    return out


def blurred(q):
    """3x3 binomial filter, borders clamped; exact in integers (q is a multiple of 16)."""
    out = np.zeros_like(q)
    w = [1, 2, 1]
    for y in range(H):
        for x in range(W):
            for k in range(3):
                s = 0
                for j in range(3):
                    for i in range(3):
                        yy = min(max(y + j - 1, 0), H - 1)
                        xx = min(max(x + i - 1, 0), W - 1)
                        s += w[j] * w[i] * q[yy, xx, k]
                out[y, x, k] = s // 16
    return out


def shifted(q):
    out = np.zeros_like(q)
    for y in range(H):
        for x in range(W):
            out[y, x] = q[y, max(x - 2, 0)]
    return out


def colour_shifted(q):
    out = q.copy()
    out[:, :, 0] = (q[:, :, 0] * 7) // 8
    out[:, :, 2] = np.minimum(q[:, :, 2] + 6000, ONE)
    return out


def constant(v):
    return np.full((H, W, 3), v, dtype=np.int64)


def ldr(q):
    return (q.astype(np.float32) / np.float32(ONE)).astype(np.float32)


def hdr(q):
    """Linear values: the LDR value times 2^(8x/W - 4), -4..3 stops across the width."""
    e = np.array([(x * 8) // W - 4 for x in range(W)], dtype=np.float32)
    scale = np.power(np.float32(2.0), e).astype(np.float32)
    return (ldr(q) * scale[None, :, None]).astype(np.float32)


def fnv1a(*imgs):
    """FNV-1a (32 bits) over the little-endian float bytes of the images in turn."""
    h = 0x811C9DC5
    for img in imgs:
        for b in np.ascontiguousarray(img, dtype="<f4").tobytes():
            h = ((h ^ b) * 0x01000193) & 0xFFFFFFFF
    return h


def pairs():
    ref = base()
    return [
        ("identical", ref, ref, 0.0),
        ("noise", noisy(ref), ref, 0.0),
        ("noise_ppd30", noisy(ref), ref, 30.0),
        ("blur", blurred(ref), ref, 0.0),
        ("shift", shifted(ref), ref, 0.0),
        ("colour", colour_shifted(ref), ref, 0.0),
        ("constant", constant(16384), constant(19661), 0.0),
        ("constant_same", constant(32768), constant(32768), 0.0),
    ]


def write_pfm(path, img):
    h, w, _ = img.shape
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(np.ascontiguousarray(img[::-1], dtype="<f4").tobytes())


def read_pfm(path):
    with open(path, "rb") as f:
        data = f.read()
    parts = data.split(maxsplit=4)
    if parts[0] != b"PF":
        sys.exit("%s: not a colour PFM file" % path)
    w, h, scale = int(parts[1]), int(parts[2]), float(parts[3])
    # the header ends after the scale's single whitespace byte
    start = len(data) - w * h * 12
    img = np.frombuffer(data[start:], dtype="<f4" if scale < 0 else ">f4").reshape(h, w, 3)
    return img[::-1].astype(np.float32)


def srgb_encode(img):
    c = np.clip(img, 0.0, 1.0).astype(np.float32)
    return np.where(c <= 0.0031308, c * 12.92, 1.055 * np.power(c, 1.0 / 2.4) - 0.055).astype(np.float32)


def big():
    """test_flip_512_time's pair: a 16-pixel checkerboard over a ramp (the
    reference) and a copy with PCG32(7, 1) noise of up to 1/4 added, clamped
    to 1: 512x512, sRGB values."""
    s = 512
    rng = pcg32(7, 1)
    r = np.zeros((s, s, 3), dtype=np.float32)
    c = np.zeros((s, s, 3), dtype=np.float32)
    for y in range(s):
        for x in range(s):
            v = np.float32((((x // 16 + y // 16) & 1) * 128 + x // 4) / 256.0)
            for k in range(3):
                r[y, x, k] = v
                c[y, x, k] = min(np.float32(1.0), np.float32(v + np.float32((next(rng) >> 24) / 1024.0)))
    return c, r


def main():
    import flip_evaluator as flip

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("images", nargs="*", help="CANDIDATE.pfm REFERENCE.pfm")
    ap.add_argument("--out", default="/tmp/rt-flip-pairs", help="where the procedural pairs are written as PFM")
    ap.add_argument("--ppd", type=float, default=0.0, help="pixels per degree (default: FLIP's 67.02)")
    ap.add_argument("--big", action="store_true", help="the 512x512 pair of test_flip_512_time")
    a = ap.parse_args()

    def params(ppd):
        return {"ppd": ppd} if ppd > 0 else {}

    if a.big:
        c, r = big()
        _, l, _ = flip.evaluate(r, c, "LDR", applyMagma=False, parameters=params(a.ppd))
        print("512x512 LDR-FLIP: %.7f" % l)
        return

    if a.images:
        if len(a.images) != 2:
            sys.exit("usage: flip_reference.py CANDIDATE.pfm REFERENCE.pfm")
        cand, ref = read_pfm(a.images[0]), read_pfm(a.images[1])
        _, l, _ = flip.evaluate(srgb_encode(ref), srgb_encode(cand), "LDR", applyMagma=False, parameters=params(a.ppd))
        _, h, p = flip.evaluate(ref, cand, "HDR", applyMagma=False, parameters=params(a.ppd))
        print("LDR-FLIP: %.6f" % l)
        print("HDR-FLIP: %.6f" % h)
        print("HDR exposures: %.4f %.4f %d" % (p["startExposure"], p["stopExposure"], p["numExposures"]))
        return

    os.makedirs(a.out, exist_ok=True)
    print("/* tools/flip_reference.py, flip-evaluator %s: name, hash of the"
          " LDR pair and of the HDR pair (candidate then reference), ppd, LDR-FLIP, HDR-FLIP */" % getattr(flip, "__version__", "1.7"))
    for name, cq, rq, ppd in pairs():
        c, r = ldr(cq), ldr(rq)
        ch, rh = hdr(cq), hdr(rq)
        _, l, _ = flip.evaluate(r, c, "LDR", applyMagma=False, parameters=params(ppd))
        _, h, _ = flip.evaluate(rh, ch, "HDR", applyMagma=False, parameters=params(ppd))
        for suffix, img in (("cand", c), ("ref", r)):
            write_pfm(os.path.join(a.out, "%s-%s-ldr.pfm" % (name, suffix)), img)
        for suffix, img in (("cand", ch), ("ref", rh)):
            write_pfm(os.path.join(a.out, "%s-%s-hdr.pfm" % (name, suffix)), img)
        print('    {"%s", 0x%08xu, 0x%08xu, %.1ff, %.7f, %.7f},' % (name, fnv1a(c, r), fnv1a(ch, rh), ppd, l, h))
    print("/* PFM files in %s */" % a.out)


if __name__ == "__main__":
    main()
