"""An exported FMU whose ``resources/diagram.bin`` is damaged refuses to instantiate, with a
logged error, and never crashes its importer.

The resource carries a CRC-32 that the binary checks before it reads anything else
(``blocks/csrc/export_resources.c``). One child process (fmpy, the FMU's own binary)
writes the resource damaged at every byte offset (four bytes of 0x7fffffff there) and in a
few thousand random multi-byte ways, instantiates the FMU after each, and counts the
refusals: a crash of the binary would end the child with a signal.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from fmpy import extract

from blocks import load_diagram
from blocks.fmu_export import export_fmu

ROOT = Path(__file__).resolve().parents[3]
RANDOM_CORRUPTIONS = 3000

CHILD = r'''
import json, random, sys
from pathlib import Path
from fmpy import read_model_description
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

unzip, count = Path(sys.argv[1]), int(sys.argv[2])
md = read_model_description(str(unzip / "modelDescription.xml"))
resource = unzip / "resources" / "diagram.bin"
good = resource.read_bytes()
fmu = FMU2Slave(guid=md.guid, unzipDirectory=str(unzip), modelIdentifier=md.coSimulation.modelIdentifier,
                instanceName="corrupted")
errors = []
callbacks = fmi2CallbackFunctions()
callbacks.logger = fmi2CallbackLoggerTYPE(lambda env, name, status, category, message: errors.append(message))


def instantiates(data):
    resource.write_bytes(data)
    try:
        fmu.instantiate(callbacks=callbacks)
    except Exception:
        return False
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.doStep(0.0, float(md.defaultExperiment.stepSize or 0.001))
    fmu.fmi2FreeInstance(fmu.component)
    return True


assert instantiates(good), "the undamaged resource must instantiate"
rng = random.Random(44)
damaged = [good[:i] + b"\xff\xff\xff\x7f"[:len(good) - i] + good[i + 4:] for i in range(len(good))]
for _ in range(count):
    data = bytearray(good)
    for _ in range(rng.randint(2, 6)):
        at = rng.randrange(len(data))
        data[at:at + rng.randint(1, 8)] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 8)))
    damaged.append(bytes(data[:len(good)]).ljust(len(good), b"\0"))
accepted = sum(instantiates(d) for d in damaged if d != good)
print(json.dumps({"tried": len(damaged), "accepted": accepted, "errors": len(errors),
                  "sample": errors[0].decode(errors="replace") if errors else ""}))
'''


def test_a_damaged_resource_is_refused_at_every_offset_and_never_crashes(tmp_path):
    fmu = export_fmu(load_diagram(ROOT / "diagrams" / "toy.yaml"), tmp_path / "toy.fmu", 2)
    unzip = Path(extract(str(fmu), str(tmp_path / "unzipped")))
    size = (unzip / "resources" / "diagram.bin").stat().st_size
    child = subprocess.run([sys.executable, "-c", CHILD, str(unzip), str(RANDOM_CORRUPTIONS)], capture_output=True,
                           text=True, timeout=1800)
    assert child.returncode == 0, f"the importer ended with {child.returncode}\n{child.stderr[-3000:]}"
    found = json.loads(child.stdout.splitlines()[-1])
    assert found["tried"] == size + RANDOM_CORRUPTIONS
    assert found["accepted"] == 0
    assert found["errors"] >= found["tried"] and "diagram.bin is damaged" in found["sample"]
