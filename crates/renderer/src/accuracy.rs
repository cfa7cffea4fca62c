//! What accuracy costs in time: error-against-time sweeps of every accuracy knob (being written).
