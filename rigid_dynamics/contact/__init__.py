"""rigid_dynamics/contact."""
