//! The terminal UI of `flexdyn-monitor` (ratatui): the summary lines of `--plain` on top, and
//! sparklines of |σ_BN|, |ω_BN|, each panel angle |θ| and the server's p99 frame lateness, one
//! column per UI refresh, newest on the right.

use std::collections::VecDeque;

use ratatui::layout::{Constraint, Direction, Layout, Rect};
use ratatui::style::{Color, Style};
use ratatui::text::Line;
use ratatui::widgets::{Block, Borders, Paragraph, Sparkline, Wrap};
use ratatui::Frame;

/// Samples each sparkline keeps (wider terminals show up to this many).
pub const HISTORY: usize = 512;

/// One named series of non-negative values.
#[derive(Clone, Debug, Default)]
pub struct Series {
    /// Title, with its unit.
    pub title: String,
    /// Oldest first.
    pub values: VecDeque<f64>,
}

impl Series {
    /// An empty series.
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            values: VecDeque::with_capacity(HISTORY),
        }
    }

    /// Appends `v` (NaN shows as an empty column), dropping the oldest beyond [`HISTORY`].
    pub fn push(&mut self, v: f64) {
        if self.values.len() == HISTORY {
            self.values.pop_front();
        }
        self.values.push_back(v);
    }

    /// The newest value.
    pub fn last(&self) -> Option<f64> {
        self.values.back().copied()
    }
}

/// What one screen shows.
#[derive(Clone, Debug, Default)]
pub struct Screen {
    /// Title line (spacecraft, mode, run state).
    pub title: String,
    /// The summary text (the `--plain` line, split for reading).
    pub summary: Vec<String>,
    /// The sparklines.
    pub series: Vec<Series>,
}

/// Scales the newest `width` values to sparkline bars: 0..=1000 of the window's maximum.
fn bars(values: &VecDeque<f64>, width: usize) -> (Vec<u64>, f64) {
    let start = values.len().saturating_sub(width);
    let shown: Vec<f64> = values.iter().skip(start).copied().collect();
    let max = shown
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    let scale = if max > 0.0 { 1000.0 / max } else { 0.0 };
    (
        shown
            .iter()
            .map(|v| {
                if v.is_finite() {
                    (v.abs() * scale).round() as u64
                } else {
                    0
                }
            })
            .collect(),
        max,
    )
}

/// Draws `screen` on the whole frame.
pub fn render(frame: &mut Frame<'_>, screen: &Screen) {
    let area = frame.area();
    let summary_height = (screen.summary.len() as u16 + 2)
        .min(area.height / 2)
        .max(3);
    let rows = Layout::default()
        .direction(Direction::Vertical)
        .constraints([Constraint::Length(summary_height), Constraint::Min(0)])
        .split(area);
    let text: Vec<Line> = screen
        .summary
        .iter()
        .map(|s| Line::from(s.as_str()))
        .collect();
    frame.render_widget(
        Paragraph::new(text).wrap(Wrap { trim: true }).block(
            Block::default()
                .borders(Borders::ALL)
                .title(format!("{} — q to quit", screen.title)),
        ),
        rows[0],
    );
    if screen.series.is_empty() {
        return;
    }
    // Two columns of sparklines.
    let per_column = screen.series.len().div_ceil(2);
    let columns = Layout::default()
        .direction(Direction::Horizontal)
        .constraints([Constraint::Percentage(50), Constraint::Percentage(50)])
        .split(rows[1]);
    for (c, column) in columns.iter().enumerate() {
        let chunk: Vec<&Series> = screen
            .series
            .iter()
            .skip(c * per_column)
            .take(per_column)
            .collect();
        if chunk.is_empty() {
            continue;
        }
        let cells = Layout::default()
            .direction(Direction::Vertical)
            .constraints(vec![Constraint::Ratio(1, chunk.len() as u32); chunk.len()])
            .split(*column);
        for (series, cell) in chunk.iter().zip(cells.iter()) {
            sparkline(frame, series, *cell);
        }
    }
}

fn sparkline(frame: &mut Frame<'_>, series: &Series, cell: Rect) {
    let width = usize::from(cell.width.saturating_sub(2));
    let (data, max) = bars(&series.values, width);
    let now = series.last().map_or("-".to_owned(), |v| format!("{v:.4e}"));
    frame.render_widget(
        Sparkline::default()
            .block(
                Block::default()
                    .borders(Borders::ALL)
                    .title(format!("{}  now {now}  max {max:.3e}", series.title)),
            )
            .data(&data)
            .max(1000)
            .style(Style::default().fg(Color::Cyan)),
        cell,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratatui::backend::TestBackend;
    use ratatui::Terminal;

    #[test]
    fn bars_scale_to_the_window_maximum() {
        let v: VecDeque<f64> = [0.0, 0.5, 1.0, f64::NAN, 2.0].into_iter().collect();
        let (b, max) = bars(&v, 4);
        assert_eq!(max, 2.0);
        assert_eq!(b, vec![250, 500, 0, 1000]);
        let mut s = Series::new("x");
        for i in 0..HISTORY + 10 {
            s.push(i as f64);
        }
        assert_eq!(s.values.len(), HISTORY);
        assert_eq!(s.values.front(), Some(&10.0));
    }

    #[test]
    fn the_screen_shows_the_summary_and_every_sparkline() {
        let mut sigma = Series::new("|σ_BN| (–)");
        let mut omega = Series::new("|ω_BN| (rad/s)");
        for i in 0..100 {
            sigma.push(0.3 * (-(i as f64) / 30.0).exp());
            omega.push(0.01 * (i as f64 / 10.0).sin().abs());
        }
        let screen = Screen {
            title: "sc1 lockstep running".into(),
            summary: vec!["t=1.000s tick=100".into(), "lateness_us p50=3.1".into()],
            series: vec![sigma, omega, Series::new("pair1 |θ1| (rad)")],
        };
        let mut term = Terminal::new(TestBackend::new(100, 30)).unwrap();
        term.draw(|f| render(f, &screen)).unwrap();
        let buf = term.backend().buffer().clone();
        let text: String = (0..buf.area.height)
            .map(|y| {
                (0..buf.area.width)
                    .map(|x| buf[(x, y)].symbol().to_owned())
                    .collect::<String>()
            })
            .collect::<Vec<_>>()
            .join("\n");
        for want in [
            "sc1 lockstep running",
            "q to quit",
            "t=1.000s tick=100",
            "|σ_BN| (–)",
            "|ω_BN| (rad/s)",
            "pair1 |θ1| (rad)",
            "now 3.0000e-1"
                .replace(
                    "3.0000e-1",
                    &format!("{:.4e}", 0.3 * (-99.0f64 / 30.0).exp()),
                )
                .as_str(),
        ] {
            assert!(text.contains(want), "{want:?} missing from\n{text}");
        }
        // The sparkline drew bars (block characters) for the data.
        assert!(text.contains('█'), "no bars drawn:\n{text}");
    }
}
