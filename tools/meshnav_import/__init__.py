"""meshnav importers: real recordings into the dataset folder of docs/formats.md (docs/real_data.md)."""
