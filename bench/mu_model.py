#!/usr/bin/python3
"""Writes models/examples/mu_3plus3_si.yaml: a 3-car multiple unit at 10 m/s (36 km/h) into a
standing identical unit, in SI, written from docs/elements.md alone (issue 37 item 1).

Every value is ILLUSTRATIVE (the shape of a modern multiple unit, not a particular vehicle;
no public source): 40 t cars (30 t body, two 4 t bogies, two 800 kg end structures), each end
structure behind a crush zone (crush_spring, 1.5-1.7 MN over 0.7 m, then stiffening) and carrying an
anticlimber (1e9 N/m faces) that meets the next car's; couplers with friction draft gears
(pin shear at 1.2 MN, then 0.25 m free travel) between the cars of a unit; bogies on rigid
rails (slider_joint) carrying the body on a vertical sliding pin with secondary springs and
dampers, preloaded with half the body's weight so the cars start in equilibrium.

    /usr/bin/python3 bench/mu_model.py [--cars-per-unit 3] [--out models/examples/mu_3plus3_si.yaml]
"""
import argparse

G = 9.81                     # [m/s^2]
CAR_PITCH = 20.0             # [m] face to face length of a car
BODY_MASS = 30000.0          # [kg]
BODY_INERTIA = BODY_MASS * (20.0**2 + 3.0**2) / 12.0   # [kg m^2] uniform 20 x 3 m block
BOGIE_MASS = 4000.0          # [kg]
BOGIE_INERTIA = BOGIE_MASS * (3.0**2 + 1.0**2) / 12.0  # [kg m^2] 3 x 1 m block
END_MASS = 800.0             # [kg] end structure (anticlimber, headstock)
END_INERTIA = END_MASS * (1.0**2 + 1.5**2) / 12.0      # [kg m^2] 1 x 1.5 m block
BODY_Y, BOGIE_Y, END_Y = 1.8, 0.5, 1.2                  # [m] heights of the centres of mass
BOGIE_X = 7.0                # [m] bogie centres from the body centre
END_X = 9.5                  # [m] end structure centre from the body centre (face at 10 m)
CRUSH_BACK_X = 8.0           # [m] the body's end frame, where the crush zone starts
SUSPENSION_STIFFNESS = 1.5e6  # [N/m] secondary suspension per bogie
SUSPENSION_DAMPING = 4.0e4   # [N s/m]
SUSPENSION_LENGTH = 0.6      # [m] loaded spring length (bogie top to body underframe)
GAP_IN_UNIT = 0.10           # [m] between the anticlimber faces of coupled cars
GAP_AT_IMPACT = 0.01         # [m] between the two units' leading faces at t = 0
SPEED = 10.0                 # [m/s] striking unit


def flow(items):
    return "{" + ", ".join(f"{k}: {v}" for k, v in items.items()) + "}"


def point(body, x, y):
    return f"{{body: {body}, at: [{x:.6g}, {y:.6g}]}}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cars-per-unit", type=int, default=3)
    parser.add_argument("--out", default="models/examples/mu_3plus3_si.yaml")
    args = parser.parse_args()
    n = args.cars_per_unit

    bodies, elements = [], []
    cars = []  # (name, body centre x, velocity)
    # Striking unit A on the left moving +x, its lead car a1 at the impact; unit B standing.
    impact_x = 0.0
    for k in range(n):
        cars.append((f"a{k + 1}", impact_x - CAR_PITCH / 2 - k * (CAR_PITCH + GAP_IN_UNIT), SPEED))
    for k in range(n):
        cars.append((f"b{k + 1}", impact_x + GAP_AT_IMPACT + CAR_PITCH / 2 + k * (CAR_PITCH + GAP_IN_UNIT), 0.0))

    for car, x, v in cars:
        body = f"{car}_body"
        bodies.append(flow({"name": body, "car": car, "mass": BODY_MASS, "inertia": f"{BODY_INERTIA:.6g}",
                            "position": f"[{x:.6g}, {BODY_Y}]", "velocity": f"[{v}, 0]"}))
        for side, sign in (("front", 1.0), ("rear", -1.0)):
            bogie = f"{car}_bogie_{side}"
            bx = x + sign * BOGIE_X
            bodies.append(flow({"name": bogie, "car": car, "mass": BOGIE_MASS, "inertia": f"{BOGIE_INERTIA:.6g}",
                                "position": f"[{bx:.6g}, {BOGIE_Y}]", "velocity": f"[{v}, 0]"}))
            top = 0.5  # [m] bogie centre to its spring seat
            underframe = BOGIE_Y + top + SUSPENSION_LENGTH - BODY_Y  # body-frame y of the spring's upper end
            preload = BODY_MASS * G / 2.0
            free_length = SUSPENSION_LENGTH + preload / SUSPENSION_STIFFNESS
            elements.append(flow({"name": f"{bogie}_rail", "type": "slider_joint", "axis": "[1, 0]",
                                  "points": f"[{point('ground', bx, BOGIE_Y)}, {point(bogie, 0, 0)}]"}))
            elements.append(flow({"name": f"{bogie}_pin", "type": "sliding_pin_joint", "axis": "[0, 1]",
                                  "points": f"[{point(body, sign * BOGIE_X, underframe)}, {point(bogie, 0, top)}]"}))
            elements.append(flow({"name": f"{bogie}_spring", "type": "linear_spring", "stiffness": SUSPENSION_STIFFNESS,
                                  "free_length": f"{free_length:.6g}",
                                  "points": f"[{point(bogie, 0, top)}, {point(body, sign * BOGIE_X, underframe)}]"}))
            elements.append(flow({"name": f"{bogie}_damper", "type": "linear_dashpot", "damping": SUSPENSION_DAMPING,
                                  "points": f"[{point(bogie, 0, top)}, {point(body, sign * BOGIE_X, underframe)}]"}))
        for side, sign in (("front", 1.0), ("rear", -1.0)):
            # Unit A's cars face +x (front towards the impact); unit B's face -x.
            facing = sign if car.startswith("a") else -sign
            end = f"{car}_end_{side}"
            ex = x + facing * END_X
            bodies.append(flow({"name": end, "car": car, "mass": END_MASS, "inertia": f"{END_INERTIA:.6g}",
                                "position": f"[{ex:.6g}, {END_Y}]", "velocity": f"[{v}, 0]"}))
            elements.append(flow({"name": f"{end}_guide", "type": "slider_joint", "axis": "[1, 0]",
                                  "points": f"[{point(body, facing * END_X, END_Y - BODY_Y)}, {point(end, 0, 0)}]"}))
            elements.append(flow({"name": f"{end}_crush", "type": "crush_spring",
                                  "curve": "[[0, 0], [0.02, 1.5e6], [0.7, 1.7e6], [0.8, 8.0e6]]",
                                  "unloading_stiffness": 2.0e8,
                                  "points": f"[{point(body, facing * CRUSH_BACK_X, END_Y - BODY_Y)}, "
                                            f"{point(end, -facing * (END_X - CRUSH_BACK_X - 1.0), 0)}]"}))

    anticlimber = {"type": "anticlimber", "horizontal_elastic_stiffness": 1.0e9, "horizontal_plastic_stiffness": 1.0e6,
                   "horizontal_yield_deflection": 0.004, "vertical_elastic_stiffness": 2.0e8,
                   "vertical_plastic_stiffness": 1.0e6, "vertical_yield_deflection": 0.002,
                   "torsional_elastic_stiffness": 1.0e8, "torsional_plastic_stiffness": 1.0e5,
                   "torsional_yield_deflection": 0.005, "face_height": 0.25}
    draft_gear = {"type": "draft_gear", "initial_stiffness": 1.0e7, "travel": 0.08, "stiffness_after_bottoming": 2.0e8,
                  "hysteresis_load": 1.0e5, "pin_shear_load": 1.2e6, "post_shear_travel": 0.25}

    def interface(first, second, coupled):
        # first's end faces second's end; the names say which ends.
        e1, e2 = f"{first[0]}_end_{first[1]}", f"{second[0]}_end_{second[1]}"
        name = f"{first[0]}_{second[0]}"
        elements.append(flow({"name": f"{name}_anticlimber", **anticlimber,
                              "points": f"[{point(e1, 0, 0)}, {point(e2, 0, 0)}]"}))
        if coupled:
            sign1 = 1.0 if first[1] == "front" else -1.0
            s1 = sign1 if first[0].startswith("a") else -sign1
            elements.append(flow({"name": f"{name}_draft_gear", **draft_gear,
                                  "points": f"[{point(first[0] + '_body', s1 * CRUSH_BACK_X, -1.0)}, "
                                            f"{point(second[0] + '_body', -s1 * CRUSH_BACK_X, -1.0)}]"}))

    interface(("a1", "front"), ("b1", "front"), coupled=False)
    for unit in "ab":
        for k in range(1, n):
            interface((f"{unit}{k}", "rear"), (f"{unit}{k + 1}", "front"), coupled=True)

    with open(args.out, "w") as out:
        out.write(f"""railcrash: 1
name: {n}+{n}-car multiple unit collision at 36 km/h (SI, illustrative)
description: >
  Written by bench/mu_model.py (issue 37): a {n}-car multiple unit at {SPEED} m/s into a standing
  identical unit. ILLUSTRATIVE values throughout (no public source; the shape of a modern
  multiple unit): 40 t cars (30 t body, two 4 t bogies, two 800 kg end structures behind
  crush zones of about 1.5 MN over 0.7 m), 1e9 N/m anticlimbers at every car end, friction
  draft gears with a 1.2 MN shear pin between the cars of a unit, bogies on rigid rails with
  preloaded secondary suspension (static equilibrium at the start).
units: SI
gravity: [0, -9.81]
bodies:
""")
        for b in bodies:
            out.write(f"  - {b}\n")
        out.write("elements:\n")
        for e in elements:
            out.write(f"  - {e}\n")
        out.write("""simulation:
  t_end: 0.6
  rtol: 1.0e-5
  output_interval: 1.0e-3
""")


if __name__ == "__main__":
    main()
