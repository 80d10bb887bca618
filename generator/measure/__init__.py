"""Cost plans (per permutation, per brick against stand-ins) and their reports."""
