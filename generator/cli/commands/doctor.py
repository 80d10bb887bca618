"""`shadermatrix doctor`: which tools are present, their versions, and whether lavapipe is there."""
HELP = "print every tool found, its version against the pin, and whether a lavapipe Vulkan device is present"


def add_arguments(p) -> None:
    pass


def run(args) -> int:
    from ..doctor_report import run_doctor
    return run_doctor()
