"""rigid_dynamics/geometry."""
