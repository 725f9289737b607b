"""Dynamic task assignment on the robots (the ChoiRbot role): protocols, records, topics."""
