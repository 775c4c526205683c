"""identify --mujoco: the identified drive train as a MuJoCo actuator model,
and how closely that model replays the servo's recorded steps.

At the output, with the duty d as the control, the drive train is

    J w' = (K V / R) d - (K^2 / R + B) w - C sgn(w)

which is MuJoCo's hinge joint with armature J, damping K^2 / R + B (the
back-EMF's damping under a voltage drive, plus the viscous drag),
frictionloss C, and a motor actuator of gear K V / R on a control in
-1..1 (its force is the duty; at the joint, gear x duty: the stall torque at
full duty)."""
import math
from pathlib import Path

from . import extras

try:
    import numpy as np
except ModuleNotFoundError as e:  # the extra servoctl[identify]
    raise extras.missing(e) from None

TIMESTEP_S = 0.0005


def mjcf(drive) -> str:
    k, r, j = drive.torque_constant.value, drive.resistance.value, drive.inertia.value
    c, b, v = drive.coulomb.value, drive.viscous.value, drive.supply_v
    gear = k * v / r
    return f"""<mujoco model="servo">
  <!-- servoctl identify at {v:.2f} V: K = kt x ratio {k:.5g} N m/A, R {r:.5g} ohm,
       J {j:.5g} kg m^2, Coulomb {c:.5g} N m, viscous {b:.5g} N m s/rad (at the output).
       The control is the duty, -1..1 of the supply. -->
  <option timestep="{TIMESTEP_S}" integrator="implicitfast"/>
  <worldbody>
    <body name="horn">
      <inertial pos="0 0 0" mass="1e-6" diaginertia="1e-12 1e-12 1e-12"/>
      <joint name="output" type="hinge" axis="0 0 1" armature="{j:.6g}" damping="{k * k / r + b:.6g}"
             frictionloss="{c:.6g}"/>
    </body>
  </worldbody>
  <actuator>
    <motor name="duty" joint="output" gear="{gear:.6g}" ctrlrange="-1 1" ctrllimited="true"
           forcerange="-1 1" forcelimited="true"/>
  </actuator>
</mujoco>
"""


def write(drive, path) -> None:
    Path(path).write_text(mjcf(drive), encoding="utf-8")


def replay(path, step):
    """The model's angle (rad) at each of the step's sample times, driven by
    the duty the servo's bridge was given (held between samples), from rest
    at the step's first angle."""
    try:
        import mujoco  # loaded for --mujoco alone
    except ModuleNotFoundError as e:  # the extra servoctl[mujoco]
        raise extras.missing(e) from None

    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    data.qpos[0] = step.samples[0].angle
    out = []
    for n, s in enumerate(step.samples):
        while data.time < s.t - step.samples[0].t - 1e-9:
            data.ctrl[0] = step.samples[n - 1].duty if n else 0.0
            mujoco.mj_step(model, data)
        out.append(float(data.qpos[0]))
    return np.array(out)


def match(path, drive) -> tuple:
    """(RMS error in degrees, as % of the travel) of the model against every
    recorded step, over each step's driven part."""
    errors, travel = [], []
    for step in drive.steps:
        model = replay(path, step)
        angles = np.array([s.angle for s in step.samples])
        driven = np.array([s.duty != 0.0 for s in step.samples])
        errors.append((model - angles)[driven])
        travel.append(abs(angles[driven][-1] - angles[0]))
    rms = math.degrees(float(np.sqrt(np.mean(np.concatenate(errors) ** 2))))
    return rms, 100.0 * rms / math.degrees(float(np.mean(travel)))
