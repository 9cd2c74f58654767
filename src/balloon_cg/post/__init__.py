"""What users look at: quantities evaluated from stored unknowns, and plots."""
