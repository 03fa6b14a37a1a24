"""The field's measures, one family per module, each scalar and batched, registered once."""
