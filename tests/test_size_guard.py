"""The size guard holds wherever a mesh is made: at every adaptive step, and with estimates that
bound the meshes the families build from above (signorini.scenes.size)."""

import pytest

import signorini
import signorini.scenes.adapt as adapt
from signorini.scenes.size import MEMORY_VARIABLE, bytes_per_dof


def test_the_memory_limit_stops_the_adaptive_loop_before_a_mesh_beyond_it_is_assembled(monkeypatch):
    limit_gb = 0.1
    fits = limit_gb * 1e9 / bytes_per_dof(2, 0, {})  # 25,000 dofs at 4 kB a dof
    assembled = []

    def counting(model, *args, **kwargs):
        assembled.append(model.mesh.p.size)
        return assemble(model, *args, **kwargs)

    assemble = adapt.assemble
    monkeypatch.setattr(adapt, "assemble", counting)
    monkeypatch.setenv(MEMORY_VARIABLE, str(limit_gb))
    result = signorini.solve_adaptive("hertz-cylinder", "0.0001%", max_dofs=10 ** 9)
    steps = result.solution.extras["adaptive"]
    assert len(assembled) >= 3 and max(assembled) <= fits, assembled
    assert steps[-1]["action"] == "memory limit" and result.problem.mesh.p.size == assembled[-1]
    assert f"memory limit of {limit_gb:.1f} GB ({MEMORY_VARIABLE}" in result.message, result.message
    assert "> target 0.0001 %" in result.message
    next_dofs = int(result.message.split("the next mesh has ")[1].split()[0])
    assert next_dofs > fits
    assert result.status == "converged" and result.estimate.pressure.relative > 1e-6
