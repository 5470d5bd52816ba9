"""meshnav importers: real recordings into the dataset folder of DESIGN §6 (docs/real_data.md)."""
