"""The SPIR-V steps every language's module goes through after its front end: with ``optimize``, ``spirv-opt
--target-env=vulkan1.1 -O`` (which validates its input itself: an invalid module is refused with the validator's
message) and ``spirv-val`` on the result; without, ``spirv-val --target-env vulkan1.1`` on the front end's
output."""
from __future__ import annotations

from pathlib import Path

from .diagnostics import failure, has_error, parse_spirv_tool
from .model import TARGET_ENV, CompileJob, CompileResult, Diagnostic
from .run import Gate


def spirv_steps(tools: dict, tmp: str, idx: int, job: CompileJob, spv: bytes, diags: list[Diagnostic],
                optimize: bool, validate: bool, gate: Gate | None = None) -> CompileResult:
    gate = gate if gate is not None else Gate()
    diags = list(diags)
    unopt = Path(tmp, f"j{idx:06d}.spv")
    unopt.write_bytes(spv)

    def val(path: Path) -> bool:
        if not validate:
            return True
        rc, text = gate.run([tools["spirv-val"], "--target-env", TARGET_ENV, str(path)])
        if rc == 0:
            return True
        found = parse_spirv_tool(text, job, "spirv-val")
        diags.extend(found if has_error(found) else [failure(job, "spirv-val", rc, text)])
        return False

    if not optimize:
        if not val(unopt):
            return CompileResult(job.key, False, None, spv, diags)
        return CompileResult(job.key, True, spv, spv, diags)
    # No spirv-val before spirv-opt: spirv-opt validates its input itself (for the same target environment)
    # and refuses an invalid module with the validator's message; the result is validated below.
    opt = Path(tmp, f"j{idx:06d}.opt.spv")
    rc, text = gate.run([tools["spirv-opt"], f"--target-env={TARGET_ENV}", "-O", str(unopt), "-o", str(opt)])
    if rc != 0 or not opt.is_file():
        found = parse_spirv_tool(text, job, "spirv-opt")
        diags.extend(found if has_error(found) else [failure(job, "spirv-opt", rc, text)])
        return CompileResult(job.key, False, None, spv, diags)
    if not val(opt):
        return CompileResult(job.key, False, None, spv, diags)
    return CompileResult(job.key, True, opt.read_bytes(), spv, diags)
