//! Machine configuration.
