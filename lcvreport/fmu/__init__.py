"""The FMUs: the interface table, the modelDescription.xml writer, the co-simulation
engine (numpy only) and the builders of the pythonfmu and the C99 FMUs."""
