"""Writes tutorial.ipynb from the cells below (so the notebook's source stays reviewable
as Python): `python make_tutorial.py`. The notebook is committed without outputs; CI
executes it headless (nbclient)."""

import nbformat as nbf

md, code = nbf.v4.new_markdown_cell, nbf.v4.new_code_cell

cells = [
    md("""# schuler from Python: simulate, navigate, compare, campaign

This notebook simulates a short drive, navigates it with GNSS and through a GNSS
outage, plots the errors against the simulated truth, and runs a small Monte-Carlo
campaign. Frames and units: body front-right-down, navigation north-east-down,
attitude roll, pitch, yaw in degrees, every column's unit in its name."""),
    code("""import matplotlib
matplotlib.use("Agg")  # headless; in Jupyter `%matplotlib inline` works as well
import matplotlib.pyplot as plt
import schuler"""),
    md("""## Simulate a drive
Five minutes at 100 Hz: a tactical-grade IMU, GNSS at 1 Hz (position 0.5 m
horizontal, 1 m vertical; velocity 0.05 m/s, 0.1 m/s), a lever arm to the antenna. The same scenario and seed give the same
bits."""),
    code("""scenario = {
    "seed": 7,
    "start": {"time": 0.0, "position": ["45.07 deg", "7.68 deg", "245 m"],
              "attitude": ["0 deg", "0 deg", "10 deg"]},
    "motion": [
        {"type": "hold", "duration": "30 s"},
        {"type": "accelerate", "to_speed": "15 m/s", "accel": "1 m/s^2"},
        {"type": "turn", "angle": "90 deg", "rate": "5 deg/s"},
        {"type": "hold", "duration": "120 s"},
        {"type": "turn", "angle": "-180 deg", "rate": "4 deg/s"},
        {"type": "hold", "duration": "60 s"},
    ],
    "imu": {"rate_hz": 100, "preset": "tactical"},
    "gnss": {"rate_hz": 1, "position_std": ["0.5 m", "0.5 m", "1 m"],
             "velocity_std": ["0.05 m/s", "0.05 m/s", "0.1 m/s"],
             "lever_arm": ["0.5 m", "0 m", "-1 m"]},
}
sim = schuler.simulate(scenario)
print(len(sim.imu), "IMU samples,", len(sim.gnss), "GNSS fixes")
sim.truth.head()"""),
    md("""## Navigate with GNSS, and through a 60-s outage
The outage is cut out of the fixes; the filter's prediction carries the solution
across it. The start is the scenario's."""),
    code("""start = dict(init_pos=(45.07, 7.68, 245.0), init_att=(0.0, 0.0, 10.0))
options = dict(output_rate=1, lever_arm=(0.5, 0.0, -1.0), imu_grade="tactical", **start)
outage = (150.0, 210.0)
gnss_cut = sim.gnss.query(f"t_s <= {outage[0]} or t_s > {outage[1]}")
with_gnss = schuler.navigate(sim.imu, gnss=sim.gnss, **options)
with_outage = schuler.navigate(sim.imu, gnss=gnss_cut, **options)
truth = sim.truth.iloc[:, :10]
e_all = schuler.compare(with_gnss.trajectory, truth).errors
e_cut = schuler.compare(with_outage.trajectory, truth, outages=[outage]).errors
print("horizontal max with GNSS %.2f m, through the outage %.2f m"
      % (e_all.horizontal_m.max(), e_cut.horizontal_m.max()))"""),
    code("""fig, ax = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
ax[0].plot(e_all.t_s, e_all.horizontal_m, label="GNSS throughout")
ax[0].plot(e_cut.t_s, e_cut.horizontal_m, label="60-s outage")
ax[0].axvspan(*outage, color="0.9")
ax[0].set_ylabel("horizontal error [m]")
ax[0].legend()
ax[1].plot(e_cut.t_s, e_cut.yaw_deg, label="yaw error (outage run)")
ax[1].set_ylabel("yaw error [deg]")
ax[1].set_xlabel("t [s]")
ax[1].legend()
fig.tight_layout()"""),
    md("""## A small Monte-Carlo campaign
`examples/montecarlo.toml` holds a scenario, `schuler nav`'s options (`[navigate]`)
and the streams the filter gets. Run `k` has seed `seed + k`; the table is the same
bits for any number of threads, and `schuler montecarlo` writes the same rows.
For a consistent filter the NEES of each 3-dof block averages near 3."""),
    code("""table = schuler.montecarlo("../montecarlo.toml", runs=8, seed=1)
table[["seed", "horizontal_rms_m", "outage_horizontal_max_m",
       "nees_position", "nees_velocity", "nees_attitude"]]"""),
    code("""fig, ax = plt.subplots(1, 2, figsize=(9, 3.5))
ax[0].bar(table.seed, table.outage_horizontal_max_m)
ax[0].set_xlabel("seed")
ax[0].set_ylabel("max horizontal error in the outage [m]")
ax[1].plot(table.seed, table.nees_position, "o", label="position")
ax[1].plot(table.seed, table.nees_attitude, "s", label="attitude")
ax[1].axhline(3.0, color="k", lw=0.8)
ax[1].set_xlabel("seed")
ax[1].set_ylabel("time-averaged NEES [-]")
ax[1].legend()
fig.tight_layout()
print(table[["nees_position", "nees_velocity", "nees_attitude"]].mean())"""),
    md("""Beyond one machine, `schuler.dask.montecarlo(client, ...)` sends the seeds to a
Dask cluster and gathers the same table (see the README's Python section)."""),
]

nb = nbf.v4.new_notebook(cells=cells, metadata={
    "kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"},
    "language_info": {"name": "python"},
})
nbf.write(nb, "tutorial.ipynb")
