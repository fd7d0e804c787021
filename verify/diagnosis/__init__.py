"""What is wrong in a failing model and how to fix it: the entries, the shape of the difference,
a confirmed repair, the inertial parameters the model implies, and the known convention traps."""
