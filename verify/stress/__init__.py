"""Hard cases that must stay numerically stable, or be refused."""
