//! `trajectory.parquet` read by row group: the writer ends its row groups with whole ticks and keeps each
//! group's first and last tick in its statistics (`swarm_records`), so a tick is found without reading the file,
//! and showing it decodes one group of about 65,536 rows. The last group decoded is kept, since the page asks
//! for consecutive ticks.

use std::path::Path;
use std::sync::{Arc, Mutex};

use swarm_records::{ParquetTable, Table, Value};

use crate::trajectory::Pose;

/// Rows of one row group decoded at most (20 bytes a pose: 80 MB). The runs' own files hold about 65,536 rows
/// a group (or one tick of a larger swarm); a file claiming more is refused rather than allowed to claim memory.
pub const MAX_GROUP_ROWS: u64 = 1 << 22;

/// A finished run's trajectory in Parquet.
pub struct ParquetTrajectory {
    table: ParquetTable,
    robots: usize,
    /// Each row group's first and last tick, in file order; consecutive.
    groups: Vec<(u64, u64)>,
    /// The last group decoded: its index and its poses, tick after tick, robots in index order.
    decoded: Mutex<Option<(usize, Arc<Vec<Pose>>)>>,
}

impl ParquetTrajectory {
    /// Opens the file at `path` of a run of `robots` robots (`None`: learn it from the first row group), or says
    /// why it cannot be shown.
    pub fn open(path: &Path, robots: Option<usize>) -> Result<ParquetTrajectory, String> {
        Self::open_with_limit(path, robots, MAX_GROUP_ROWS)
    }

    /// [`ParquetTrajectory::open`], refusing row groups of more than `max_group_rows` rows.
    fn open_with_limit(
        path: &Path,
        robots: Option<usize>,
        max_group_rows: u64,
    ) -> Result<ParquetTrajectory, String> {
        let table = ParquetTable::open(Table::Trajectory, path).map_err(|e| e.to_string())?;
        let name = path.display();
        let mut groups: Vec<(u64, u64)> = Vec::with_capacity(table.row_groups());
        let mut robots = robots;
        for index in 0..table.row_groups() {
            let (first, last) = table.ticks(index).ok_or_else(|| {
                format!(
                    "{name}: row group {index} does not say which ticks it holds (no statistics)"
                )
            })?;
            if let Some(&(_, previous)) = groups.last()
                && Some(first) != previous.checked_add(1)
            {
                return Err(format!(
                    "{name}: row group {index} starts at tick {first}, not after tick {previous}"
                ));
            }
            let ticks = last
                .checked_sub(first)
                .and_then(|span| span.checked_add(1))
                .ok_or_else(|| format!("{name}: row group {index} ends before it starts"))?;
            let rows = table.rows(index);
            if rows > max_group_rows {
                return Err(format!(
                    "{name}: row group {index} holds {rows} rows, more than the viewer reads at once \
                     ({max_group_rows}): it was not written by a run"
                ));
            }
            let per_tick = *robots.get_or_insert((rows / ticks) as usize);
            if per_tick == 0 || rows != ticks.saturating_mul(per_tick as u64) {
                return Err(format!(
                    "{name}: row group {index} has {rows} rows for ticks {first} to {last}, not one per robot \
                     ({per_tick}) and tick"
                ));
            }
            groups.push((first, last));
        }
        Ok(ParquetTrajectory {
            table,
            robots: robots.unwrap_or(0),
            groups,
            decoded: Mutex::new(None),
        })
    }

    /// Robots per tick.
    pub fn robots(&self) -> usize {
        self.robots
    }

    /// The first and last ticks.
    pub fn ticks(&self) -> Option<(u64, u64)> {
        Some((self.groups.first()?.0, self.groups.last()?.1))
    }

    /// Every robot's pose at `tick`, by robot index.
    pub fn read_tick(&self, tick: u64) -> Result<Vec<Pose>, String> {
        let (first, last) = self.ticks().ok_or("no tick recorded")?;
        if !(first..=last).contains(&tick) {
            return Err(format!("tick {tick} is outside {first}..={last}"));
        }
        let group = self.groups.partition_point(|&(_, end)| end < tick);
        let poses = self.group_poses(group)?;
        let start = (tick - self.groups[group].0) as usize * self.robots;
        Ok(poses[start..start + self.robots].to_vec())
    }

    /// The poses of row group `group`, decoded now or kept from the last call.
    fn group_poses(&self, group: usize) -> Result<Arc<Vec<Pose>>, String> {
        let mut decoded = self.decoded.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((kept, poses)) = decoded.as_ref()
            && *kept == group
        {
            return Ok(Arc::clone(poses));
        }
        let (first, last) = self.groups[group];
        let mut poses = vec![Pose::ABSENT; (last - first + 1) as usize * self.robots];
        let robots = self.robots;
        self.table
            .read_row_group(group, |_, values| {
                let (tick, robot, pose) = pose_of(values)?;
                let slot = tick
                    .checked_sub(first)
                    .filter(|&t| t <= last - first && robot < robots)
                    .map(|t| t as usize * robots + robot)
                    .ok_or_else(|| {
                        format!("tick {tick}, robot {robot} is not in this row group")
                    })?;
                poses[slot] = pose;
                Ok(())
            })
            .map_err(|e| e.to_string())?;
        let poses = Arc::new(poses);
        *decoded = Some((group, Arc::clone(&poses)));
        Ok(poses)
    }
}

/// A trajectory row's tick, robot and pose (the reader has checked the columns' types).
fn pose_of(values: &[Value<'_>]) -> Result<(u64, usize, Pose), String> {
    match values {
        [
            Value::Int64(tick),
            Value::Int32(robot),
            _,
            Value::Float(x),
            Value::Float(y),
            Value::Float(heading),
            Value::Int32(r),
            Value::Int32(g),
            Value::Int32(b),
            Value::Boolean(alive),
        ] => Ok((
            *tick as u64,
            *robot as u32 as usize,
            Pose {
                x: *x,
                y: *y,
                heading: *heading,
                led: [*r as u8, *g as u8, *b as u8],
                alive: *alive,
            },
        )),
        _ => Err("the row is not a trajectory row".to_owned()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run folder whose `trajectory.parquet` holds `ticks` ticks of `robots` robots, in one row group.
    fn run(ticks: u64, robots: usize) -> tempfile::TempDir {
        let dir = tempfile::tempdir().expect("temp dir");
        let mut csv = String::from(crate::trajectory::HEADER);
        csv.push('\n');
        for tick in 0..ticks {
            for robot in 0..robots {
                csv += &format!("{tick},{robot},r{robot},{robot}.5,{tick}.25,0.5,255,0,0,1\n");
            }
        }
        std::fs::write(dir.path().join("trajectory.csv"), csv).expect("written");
        swarm_records::export(dir.path(), swarm_records::Format::Parquet).expect("exported");
        dir
    }

    #[test]
    fn reads_any_tick_of_a_run() {
        let dir = run(5, 3);
        let trajectory =
            ParquetTrajectory::open(&dir.path().join("trajectory.parquet"), None).expect("opened");
        assert_eq!((trajectory.robots(), trajectory.ticks()), (3, Some((0, 4))));
        let poses = trajectory.read_tick(3).expect("tick 3");
        assert_eq!(
            (poses[2].x, poses[2].y, poses[2].led),
            (2.5, 3.25, [255, 0, 0])
        );
        assert!(trajectory.read_tick(5).is_err());
    }

    #[test]
    fn a_row_group_larger_than_the_limit_is_refused_before_it_is_read() {
        let dir = run(4, 2);
        let path = dir.path().join("trajectory.parquet");
        let problem = ParquetTrajectory::open_with_limit(&path, Some(2), 7)
            .err()
            .expect("refused");
        assert!(problem.contains("row group 0 holds 8 rows"), "{problem}");
        assert!(ParquetTrajectory::open_with_limit(&path, Some(2), 8).is_ok());
    }
}
