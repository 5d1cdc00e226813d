//! The real-time thread. Filled by issue 4 ("The real-time pipeline").
