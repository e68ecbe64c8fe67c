//! The artificial pheromone field (docs/tasks.md 5.2): one scalar grid per channel over the arena, with deposits at
//! robot positions, per-channel evaporation `tau <- (1 - rho) tau` and an optional 3 x 3 diffusion blur of weight
//! D, stepped once per tick after physics. Concentrations never go below zero (negative deposits erase).

use swarm_contract::messages::PHEROMONE_CHANNELS;

use crate::geometry::Vec2;

/// Evaporation and diffusion of one channel, per tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelRates {
    /// Fraction rho that evaporates every tick.
    pub evaporation: f32,
    /// Weight D of the 3 x 3 blur every tick (0 = no diffusion).
    pub diffusion: f32,
}

impl ChannelRates {
    /// Neither evaporation nor diffusion: what is deposited stays.
    pub const STILL: ChannelRates = ChannelRates {
        evaporation: 0.0,
        diffusion: 0.0,
    };
}

/// The field of every channel.
#[derive(Debug, Clone)]
pub struct PheromoneField {
    origin: Vec2,
    cell: f32,
    nx: usize,
    ny: usize,
    rates: [ChannelRates; PHEROMONE_CHANNELS],
    /// Whether anything was ever deposited in each channel; untouched channels are all zero and are not stepped.
    touched: [bool; PHEROMONE_CHANNELS],
    values: Vec<f32>,
    scratch: Vec<f32>,
    /// False for the field of a run without a pheromone medium: deposits are ignored and every reading is 0.
    active: bool,
}

impl PheromoneField {
    /// A zero field over `min..max` with square cells of side `cell` metres.
    pub fn new(min: Vec2, max: Vec2, cell: f32, rates: [ChannelRates; PHEROMONE_CHANNELS]) -> Self {
        let cell = cell.max(0.005);
        let nx = (((max.x - min.x) / cell).ceil() as usize).max(1);
        let ny = (((max.y - min.y) / cell).ceil() as usize).max(1);
        let n = nx * ny * PHEROMONE_CHANNELS;
        Self {
            origin: min,
            cell,
            nx,
            ny,
            rates,
            touched: [false; PHEROMONE_CHANNELS],
            values: vec![0.0; n],
            scratch: vec![0.0; n],
            active: true,
        }
    }

    /// A field of one cell that nothing deposits into: the arena of a run without a pheromone medium, which then
    /// costs no memory whatever its size.
    pub fn off(origin: Vec2) -> Self {
        Self {
            active: false,
            ..Self::new(
                origin,
                origin,
                1.0,
                [ChannelRates::STILL; PHEROMONE_CHANNELS],
            )
        }
    }

    /// Whether the run has a pheromone medium (the field of a run without one is never deposited into).
    pub fn is_active(&self) -> bool {
        self.active
    }

    /// The corner of cell (0, 0), at the arena's minimum.
    pub fn origin(&self) -> Vec2 {
        self.origin
    }

    /// Grid size (columns, rows) and cell side in metres.
    pub fn dimensions(&self) -> (usize, usize, f32) {
        (self.nx, self.ny, self.cell)
    }

    fn cell_of(&self, p: Vec2) -> (usize, usize) {
        let q = (p - self.origin) / self.cell;
        (
            (q.x.floor().max(0.0) as usize).min(self.nx - 1),
            (q.y.floor().max(0.0) as usize).min(self.ny - 1),
        )
    }

    fn at(&self, channel: usize, x: usize, y: usize) -> f32 {
        self.values[(channel * self.ny + y) * self.nx + x]
    }

    /// Concentration of `channel` in cell (x, y).
    pub fn cell_value(&self, channel: usize, x: usize, y: usize) -> f32 {
        if channel < PHEROMONE_CHANNELS && x < self.nx && y < self.ny {
            self.at(channel, x, y)
        } else {
            0.0
        }
    }

    /// Adds `amount` to the cell under `p` (negative amounts erase, never below zero).
    pub fn deposit(&mut self, channel: usize, p: Vec2, amount: f32) {
        if !self.active || channel >= PHEROMONE_CHANNELS || amount == 0.0 || !amount.is_finite() {
            return;
        }
        let (x, y) = self.cell_of(p);
        self.touched[channel] = true;
        let v = &mut self.values[(channel * self.ny + y) * self.nx + x];
        *v = (*v + amount).max(0.0);
    }

    /// Concentration of `channel` in the cell under `p`.
    pub fn concentration(&self, channel: usize, p: Vec2) -> f32 {
        if !self.touched.get(channel).copied().unwrap_or(false) {
            return 0.0;
        }
        let (x, y) = self.cell_of(p);
        self.cell_value(channel, x, y)
    }

    /// Gradient (d/dx, d/dy) of `channel` at `p` in the arena frame, by central differences between the
    /// neighbouring cells (one-sided at the border).
    pub fn gradient(&self, channel: usize, p: Vec2) -> Vec2 {
        if !self.touched.get(channel).copied().unwrap_or(false) {
            return Vec2::ZERO;
        }
        let (x, y) = self.cell_of(p);
        let (x0, x1) = (x.saturating_sub(1), (x + 1).min(self.nx - 1));
        let (y0, y1) = (y.saturating_sub(1), (y + 1).min(self.ny - 1));
        let gx = if x1 > x0 {
            (self.at(channel, x1, y) - self.at(channel, x0, y)) / ((x1 - x0) as f32 * self.cell)
        } else {
            0.0
        };
        let gy = if y1 > y0 {
            (self.at(channel, x, y1) - self.at(channel, x, y0)) / ((y1 - y0) as f32 * self.cell)
        } else {
            0.0
        };
        Vec2::new(gx, gy)
    }

    /// Sets `channel` to zero in every cell whose centre lies within `radius` metres of `centre` (a loop function
    /// erasing the trail of an exhausted source, docs/tasks.md 5.2); returns how many cells held pheromone.
    pub fn clear_disc(&mut self, channel: usize, centre: Vec2, radius: f32) -> usize {
        if channel >= PHEROMONE_CHANNELS || !self.touched[channel] {
            return 0;
        }
        let (lo, hi) = (
            self.cell_of(centre - Vec2::splat(radius)),
            self.cell_of(centre + Vec2::splat(radius)),
        );
        let mut cleared = 0;
        for y in lo.1..=hi.1 {
            for x in lo.0..=hi.0 {
                let c = self.origin + Vec2::new(x as f32 + 0.5, y as f32 + 0.5) * self.cell;
                let v = &mut self.values[(channel * self.ny + y) * self.nx + x];
                if (c - centre).length() <= radius && *v > 0.0 {
                    *v = 0.0;
                    cleared += 1;
                }
            }
        }
        cleared
    }

    /// One tick of evaporation and diffusion for every channel. The blur averages each cell's 3 x 3 neighbourhood
    /// (cells outside the arena do not count) and mixes it in with weight D.
    pub fn step(&mut self) {
        let (nx, ny) = (self.nx, self.ny);
        for (ch, rates) in self.rates.iter().enumerate() {
            if !self.touched[ch] || (rates.evaporation == 0.0 && rates.diffusion == 0.0) {
                continue;
            }
            let base = ch * nx * ny;
            let keep = (1.0 - rates.evaporation).clamp(0.0, 1.0);
            if rates.diffusion > 0.0 {
                let d = rates.diffusion.clamp(0.0, 1.0);
                for y in 0..ny {
                    for x in 0..nx {
                        let (mut sum, mut n) = (0.0f32, 0.0f32);
                        for yy in y.saturating_sub(1)..=(y + 1).min(ny - 1) {
                            for xx in x.saturating_sub(1)..=(x + 1).min(nx - 1) {
                                sum += self.values[base + yy * nx + xx];
                                n += 1.0;
                            }
                        }
                        let v = self.values[base + y * nx + x];
                        self.scratch[base + y * nx + x] = keep * ((1.0 - d) * v + d * sum / n);
                    }
                }
                self.values[base..base + nx * ny]
                    .copy_from_slice(&self.scratch[base..base + nx * ny]);
            } else {
                self.values[base..base + nx * ny]
                    .iter_mut()
                    .for_each(|v| *v *= keep);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field(evaporation: f32, diffusion: f32) -> PheromoneField {
        let rates = [ChannelRates {
            evaporation,
            diffusion,
        }; PHEROMONE_CHANNELS];
        PheromoneField::new(Vec2::splat(-1.0), Vec2::splat(1.0), 0.05, rates)
    }

    #[test]
    fn evaporation_scales_by_one_minus_rho_per_tick() {
        let mut f = field(0.001, 0.0);
        f.deposit(0, Vec2::ZERO, 1.0);
        for _ in 0..10 {
            f.step();
        }
        assert!((f.concentration(0, Vec2::ZERO) - 0.999f32.powi(10)).abs() < 1e-6);
        assert_eq!(f.concentration(1, Vec2::ZERO), 0.0);
    }

    #[test]
    fn diffusion_mixes_the_3x3_mean_in_with_weight_d() {
        let mut f = field(0.0, 0.05);
        f.deposit(0, Vec2::new(0.01, 0.01), 1.0);
        f.step();
        let centre = f.concentration(0, Vec2::new(0.01, 0.01));
        assert!((centre - (0.95 + 0.05 / 9.0)).abs() < 1e-6);
        assert!((f.concentration(0, Vec2::new(0.06, 0.01)) - 0.05 / 9.0).abs() < 1e-6);
    }

    #[test]
    fn gradient_points_up_the_slope_and_negative_deposits_stop_at_zero() {
        let mut f = field(0.0, 0.0);
        f.deposit(0, Vec2::new(0.06, 0.01), 1.0);
        assert!(f.gradient(0, Vec2::new(0.01, 0.01)).x > 0.0);
        f.deposit(0, Vec2::new(0.06, 0.01), -5.0);
        assert_eq!(f.concentration(0, Vec2::new(0.06, 0.01)), 0.0);
    }

    #[test]
    fn clear_disc_zeroes_only_the_cells_within_the_radius() {
        let mut f = field(0.0, 0.0);
        f.deposit(0, Vec2::new(0.01, 0.01), 1.0);
        f.deposit(0, Vec2::new(0.51, 0.01), 1.0);
        f.deposit(1, Vec2::new(0.01, 0.01), 1.0);
        assert_eq!(f.clear_disc(0, Vec2::ZERO, 0.2), 1);
        assert_eq!(f.concentration(0, Vec2::new(0.01, 0.01)), 0.0);
        assert_eq!(f.concentration(0, Vec2::new(0.51, 0.01)), 1.0);
        assert_eq!(f.concentration(1, Vec2::new(0.01, 0.01)), 1.0);
    }
}
