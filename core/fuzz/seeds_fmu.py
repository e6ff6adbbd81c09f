"""Writes the hand-made seeds of core/fuzz/corpus_fmu (fuzz_fmu.c): the resource files the Python
exporter writes for seven models (each plant, Model I and II, a heat balance, GMS; both integrators),
each followed by a program of FMI calls in fuzz_fmu.c's encoding. Run from the repository root with the
package installed: python core/fuzz/seeds_fmu.py core/fuzz/corpus_fmu"""

from __future__ import annotations

import struct
import sys
import zipfile
from pathlib import Path

import thermofriction as tf
from thermofriction.fmu import export_fmu


def num(x: float) -> bytes:
    return bytes([0]) + struct.pack("<d", x)  # selector 0: the raw bits of a double


class Program:
    def __init__(self, tfm: str):
        self.tfm = tfm
        self.vars = [int(line.split()[1]) for line in tfm.splitlines() if line.startswith("var ")][:64]
        self.b = bytearray()

    def vr(self, name_or_vr) -> bytes:
        if isinstance(name_or_vr, int) and name_or_vr < 16:
            return bytes([name_or_vr])
        i = self.vars.index(name_or_vr)
        return bytes([96 + (i - 96) % len(self.vars)])

    def setup(self, tol=1e-6, start=0.0, stop=None):
        self.b += bytes([0, 3 | (4 if stop is not None else 0)]) + num(tol) + num(start) + num(
            1.0 if stop is None else stop)

    def enter(self):
        self.b += bytes([1])

    def exit(self):
        self.b += bytes([2])

    def set(self, vr, value):
        self.b += bytes([3, 1]) + self.vr(vr) + num(value) + bytes([0])

    def get(self, *vrs):
        self.b += bytes([4, len(vrs)]) + b"".join(self.vr(v) for v in vrs) + bytes([0])

    def slope(self, vr, value):
        self.b += bytes([5, 1, vr, 1]) + num(value) + bytes([0])

    def step(self, exponent=4, h=None):
        self.b += bytes([6, 0, 0, exponent - 3]) if h is None else bytes([6, 1]) + num(h)

    def save(self):
        self.b += bytes([7, 1])

    def restore(self):
        self.b += bytes([7, 0])

    def raw(self, *values):
        self.b += bytes(values)

    def data(self, logging=True) -> bytes:
        text = self.tfm.encode()
        return struct.pack("<H", len(text)) + text + bytes([2 | (32 if logging else 0)]) + bytes(self.b)


def models():
    mass = tf.Model(plant=tf.MassPlant(mass=0.35), name="mass-lugre",
                    friction=tf.LuGre(sigma0=3.0e4, sigma1=0.8, sigma2=0.6, fc=1.3, fs=1.75, vs=4e-3))
    gms = tf.Model(plant=tf.PrescribedMotion(), name="prescribed-gms",
                   friction=tf.GMS(k=(1.2e5, 6.0e4, 4.5e4), w=(0.25, 0.35, 0.4), C=15.0, fc=0.8, fs=1.1, vs=1.5e-3))
    yield "mass-lugre", mass, {}
    yield "mass-lugre-rt", mass, {"integrator": "realtime", "step": 1e-4}
    yield "gms", gms, {}
    yield "gms-rt", gms, {"integrator": "realtime", "step": 1e-4}
    for preset in ("li2009-model-i", "li2009-model-ii", "li2009-self-heating"):
        yield preset, tf.load_model(preset), {}
    yield "li2009-model-ii-rt", tf.load_model("li2009-model-ii"), {"integrator": "realtime", "step": 1e-5}


def tfm_of(model, tmp: Path, **kw) -> str:
    path = tmp / "m.fmu"
    export_fmu(model, path, **kw)
    with zipfile.ZipFile(path) as z:
        return z.read("resources/model.tfm").decode()


def programs(tfm: str):
    thermal = "temperature_input 1" in tfm or "heat 1" in tfm
    # a run: set-up, inputs, steps with slopes, outputs
    p = Program(tfm)
    p.setup()
    p.enter()
    if thermal:
        p.set(1, 35.0)
    p.set(0, 1.0)
    p.exit()
    for k in range(12):
        p.set(0, 1.0 + 0.5 * k)
        p.slope(0, 5e3)
        p.step(4)
        p.get(2, 3, 4)
    yield "run", p
    # parameters changed before and during the run, states saved and restored, a reset
    p = Program(tfm)
    p.setup(1e-4)
    p.enter()
    for v in p.vars[:6]:
        p.set(v, 1.0)
    p.exit()
    p.step(3)
    p.save()
    for v in p.vars[:8]:
        p.set(v, 2.0)
        p.step(4)
    p.restore()
    p.step(3)
    p.raw(9)  # reset
    p.setup()
    p.enter()
    p.exit()
    p.step(5)
    p.raw(10)  # terminate
    p.step(4)
    yield "params-state-reset", p
    # what must be refused: huge steps, undeclared references, bad temperatures, NULL derivatives
    p = Program(tfm)
    p.setup(start=1e300)
    p.setup(start=5.0)
    p.enter()
    p.set(9, 1.0)
    p.get(7, 15)
    if thermal:
        p.set(1, -300.0)
        p.set(1, 299.0)
    p.exit()
    p.step(h=1e300)
    p.step(h=1e11)
    p.step(h=1e-9)
    p.raw(5, 1, 0, 1)  # input derivatives with NULL value references
    p.b += num(1.0) + bytes([1])
    if thermal:
        p.slope(1, 1e7)
    p.step(3)
    p.slope(0, float("nan"))
    p.step(4)
    p.raw(13, 0, 13, 1, 13, 2, 1, 12, 3, 1, 0)
    yield "refusals", p
    # the state machine (issue 41): a stop time, calls outside their modes, states across modes
    p = Program(tfm)
    p.setup(stop=2e-3)
    p.raw(10)  # terminate before the initialization: refused
    p.enter()
    if thermal:
        p.set(1, 35.0)
    p.save()  # a state from initialization mode
    p.exit()
    p.restore()  # ... into step mode: refused
    p.raw(7, 1)  # a state from step mode
    p.step(3)
    p.step(3)  # ends on the stop time
    p.step(3)  # past it: refused
    p.raw(10)  # terminate
    p.restore()  # allowed: the instance stays terminated
    p.step(3)
    p.set(0, 1.0)
    p.raw(10)
    p.raw(9)  # reset: no stop time any more
    p.restore()  # a state from step mode into an instantiated instance: refused
    p.setup()
    p.enter()
    p.exit()
    p.step(h=1.0)
    yield "modes", p


def main(out: Path):
    import tempfile

    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for name, model, kw in models():
            tfm = tfm_of(model, Path(tmp), **kw)
            for what, p in programs(tfm):
                (out / f"seed-{name}-{what}").write_bytes(p.data())
            # the step variable of the real-time integrator set to 1e-300 before initialisation
            if kw.get("integrator") == "realtime":
                p = Program(tfm)
                step = next(int(line.split()[1]) for line in tfm.splitlines() if line.startswith("var ") and " step " in line)
                p.setup()
                p.enter()
                p.set(step, 1e-300)
                p.exit()
                p.step(4)
                (out / f"seed-{name}-tiny-step").write_bytes(p.data())
            # a wrong GUID
            p = Program(tfm)
            data = bytearray(p.data())
            data[2 + len(tfm.encode())] = 1
            (out / f"seed-{name}-wrong-guid").write_bytes(bytes(data))
    # resource files that are broken: no header, a bad line, an unknown role, no guid
    for i, text in enumerate(["", "thermofriction-fmu 1\n", "thermofriction-fmu 2\nplant 9 9\n",
                              "thermofriction-fmu 2\nguid {x}\nvar 16 nonsense 0 0 0 1.0\n",
                              "thermofriction-fmu 2\nvar 99999 p 0 0 0 1.0\nguid {x}\n"]):
        (out / f"seed-broken-{i}").write_bytes(struct.pack("<H", len(text)) + text.encode() + bytes([2, 0, 1, 2, 6]))


if __name__ == "__main__":
    main(Path(sys.argv[1]))
