"""Per-robot packages: descriptions (data), simulated hardware settings, resolvers and process modules."""
