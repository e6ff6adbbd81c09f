"""Evidence for the paper presets' choices (docs/paper.md): step size per cycle against
temperature for the shipped Model I and Model II presets, and how it depends on the two
masses the paper does not give. Run: python examples/li2009_presets.py"""

import dataclasses

import numpy as np

import thermofriction as tf

TEMPS = (30.8, 33.0, 35.7, 38.4, 40.0, 41.5)


def step_um(model, T, duration=2.0):
    """Mean step per cycle over the last 8 of 10 cycles, in micrometres."""
    res = tf.simulate(model, duration, temperature=T, sample_rate=1000)
    return float(np.mean(res.step_sizes[2:]) * 1e6)


def main():
    print("Step per cycle [um] under the 30 V, 5 Hz sawtooth (rise 0.999)")
    print("model          " + "".join(f"{T:>8.1f}" for T in TEMPS))
    for name in ("li2009-model-i", "li2009-model-ii"):
        model = tf.load_model(name)
        print(f"{name:15s}" + "".join(f"{step_um(model, T):8.3f}" for T in TEMPS))
    offset = tf.load_model("li2009-model-ii")
    offset = dataclasses.replace(offset, thermal=tf.ModelII(offset.thermal.dF, form="offset"))
    print(f"{'model-ii offset':15s}" + "".join(f"{step_um(offset, T):8.3f}" for T in TEMPS))

    print("\nModel I, step per cycle [um] against the unknown masses (m stage, m_e end effector)")
    base = tf.load_model("li2009-model-i")
    print("m [kg]  m_e [kg]" + "".join(f"{T:>8.1f}" for T in (30.8, 35.7, 41.5)))
    for m in (0.01, 0.05, 0.2):
        for me in (0.01, 0.02, 0.05, 0.1):
            plant = dataclasses.replace(base.plant, mass=m, end_effector_mass=me)
            model = dataclasses.replace(base, plant=plant)
            print(f"{m:6.2f}  {me:8.2f}" + "".join(f"{step_um(model, T):8.3f}" for T in (30.8, 35.7, 41.5)))

    print("\nModel I with the sawtooth's rise fraction 0.99 (2 ms fall) instead of 0.999 (0.2 ms)")
    slow = dataclasses.replace(base, input=tf.Sawtooth(30, 5, rise=0.99))
    print("rise 0.99      " + "".join(f"{step_um(slow, T):8.3f}" for T in TEMPS))


if __name__ == "__main__":
    main()
