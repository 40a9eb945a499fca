"""Whether a `hadynet residual --fix` JSON names a plant effect (issue 12's
benchmarks; not a test). One rule per plant effect, shared by
bench/residual_detection.sh and bench/residual_two_effects.sh:

  sensor-delay  the delay in steps;
  crosstalk     plant pairs (fc0<-fc1, fc1<-fc2, fc2<-fc3, fc3<-fc4, fc4<-fc3):
                the winner's and, since stop 60, every further pair of the
                group the fix removes (augmentation.pairs);
  tension-leak  f5 -> fc6 with a gain within 0.5-1.5 times the plant's;
  friction      tendon channels (f*);
  drift         a load drift on loadcells;
  saturation    loadcell upper rails within 10 % of the plant's;
  input-delay   the commands the plant's delay earlier as inputs (lag<d>_u*);
  sensor-curve  curves on loadcells only, the first (the winner's) reading
                within 25 % of the plant's 50 (L / 50)^E at its highest
                fitted knot L (since stop 79 a curve can end with a knot at
                the rated top, 50 N, that reads its own level by
                construction: the datasheet's, not a fit, so not read).

Usable as a module (names(effect, strength, fix)) or run as
`residual_named.py EFFECT STRENGTH FIX_JSON_FILE` (prints yes or no).
"""
import json
import re
import sys

PLANT_CROSSTALK_PAIRS = {("fc0", "fc1"), ("fc1", "fc2"), ("fc2", "fc3"), ("fc3", "fc4"), ("fc4", "fc3")}


def top_fitted_knot(curve, rated_top=50.0):
    """The index of a curve's highest fitted knot (a JSON curve: level,
    reading): a last knot at the loadcells' rated top (50 N) that reads its
    own level is the datasheet's, not a fit (CalibrationCurves::rated_top)."""
    levels, readings = curve["level"], curve["reading"]
    k = len(levels) - 1
    while k > 0 and levels[k] >= rated_top - 1e-9 and readings[k] == levels[k]:
        k -= 1
    return k


def names(effect, strength, fix):
    """True when the fix's augmentation (confirmed or not) has the plant
    effect `effect` at `strength` with the right parameter."""
    aug = fix.get("augmentation") or {}
    named_effect = aug.get("effect", "-")
    channels = aug.get("channels", [])
    if effect == "sensor-delay":
        return named_effect == "sensor-delay" and aug.get("delay_steps") == int(strength)
    if effect == "crosstalk":
        pairs = [(p["target"], p["source"]) for p in aug.get("pairs", [])] or [(channels[0] if channels else None,
                                                                                  aug.get("source"))]
        return named_effect == "crosstalk" and bool(channels) and all(p in PLANT_CROSSTALK_PAIRS for p in pairs)
    if effect == "tension-leak":
        gain = aug.get("gain", 0.0)
        return (named_effect == "crosstalk" and channels == ["fc6"] and aug.get("source") == "f5"
                and 0.5 * strength <= gain <= 1.5 * strength)
    if effect == "friction":
        return named_effect == "friction" and bool(channels) and all(re.fullmatch(r"f\d+", c) for c in channels)
    if effect == "drift":
        return named_effect == "drift-load" and bool(channels) and all(c.startswith("fc") for c in channels)
    if effect == "saturation":
        rails = [float(x) for x in re.findall(r"fc\d+ <= ([0-9.eE+-]+)", aug.get("description", ""))]
        return named_effect == "saturation" and bool(rails) and all(abs(r - strength) <= 0.1 * strength for r in rails)
    if effect == "input-delay":
        lags = aug.get("derived_inputs", [])
        return named_effect == "input-delay" and bool(lags) and all(x.startswith("lag%d_" % int(strength)) for x in lags)
    if effect == "sensor-curve":
        curves = aug.get("curves", [])

        def plant_reading(level):
            return 50.0 * (max(level, 0.0) / 50.0) ** strength

        if not (named_effect == "sensor-curve" and bool(curves) and all(c["channel"].startswith("fc") for c in curves)):
            return False
        k = top_fitted_knot(curves[0])
        level, reading = curves[0]["level"][k], curves[0]["reading"][k]
        return abs(reading - plant_reading(level)) <= 0.25 * plant_reading(level)
    raise ValueError("residual_named: no naming rule for effect " + effect)


if __name__ == "__main__":
    if len(sys.argv) != 4 or sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0 if len(sys.argv) == 2 else 2)
    fix = json.load(open(sys.argv[3])).get("fix", {})
    print("yes" if bool(fix.get("changed")) and names(sys.argv[1], float(sys.argv[2]), fix) else "no")
