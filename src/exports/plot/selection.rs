//! What every figure of a run draws: the channel of an RGB run and the heat maps' scale.

/// The channel drawn and the heat maps' scale, shared by every figure of a run.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Selection {
    pub channel: usize,
    pub rgb: bool,
    pub log: bool,
}

impl Selection {
    /// The `channel` value of the rows drawn (`None` for mono runs, which have no column).
    pub(super) fn channel_name(self) -> Option<&'static str> {
        self.rgb.then(|| ["r", "g", "b"][self.channel])
    }

    /// What figure titles add for an RGB run.
    pub(super) fn suffix(self) -> String {
        self.channel_name().map_or(String::new(), |c| format!(", channel {c}"))
    }

    /// What captions add for an RGB run.
    pub(super) fn note(self) -> String {
        self.channel_name().map_or(String::new(), |c| format!(" Channel {c} of an RGB run."))
    }
}
