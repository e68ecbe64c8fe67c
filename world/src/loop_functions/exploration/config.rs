//! The lists of the `<exploration>` element: `tasks` (`x,y,type,value,window` entries separated by `;`) and
//! `robot_types` (`controller:type` pairs separated by commas or spaces). Errors are messages without the
//! element's location, which the caller adds.

use swarm_allocation::Kind;
use swarm_navigation::wire::exploration::MAX_TASKS;

use crate::geometry::Vec2;

/// One task as the configuration gives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TaskSpec {
    /// Where it is (m).
    pub position: Vec2,
    /// Its type.
    pub kind: Kind,
    /// Its value u_j.
    pub value: f32,
    /// Its time window W_j: seconds from the start of the run.
    pub window: f64,
}

/// The type `1` or `2`.
fn kind(text: &str) -> Option<Kind> {
    match text.trim() {
        "1" => Some(Kind::One),
        "2" => Some(Kind::Two),
        _ => None,
    }
}

/// The number of a type.
pub fn kind_number(kind: Kind) -> u8 {
    match kind {
        Kind::One => 1,
        Kind::Two => 2,
    }
}

/// A finite number.
fn number(text: &str) -> Option<f64> {
    text.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

/// Reads `tasks`: `x,y,type,value,window` entries separated by `;` (a `;` after the last entry is allowed).
pub fn parse_tasks(text: &str) -> Result<Vec<TaskSpec>, String> {
    let text = text.trim();
    let text = text.strip_suffix(';').unwrap_or(text);
    if text.trim().is_empty() {
        return Err(
            "`tasks` lists no task: give `x,y,type,value,window` entries separated by `;`".into(),
        );
    }
    let entries: Vec<&str> = text.split(';').collect();
    if entries.len() > MAX_TASKS {
        return Err(format!(
            "`tasks` lists {} tasks; at most {MAX_TASKS}",
            entries.len()
        ));
    }
    entries
        .iter()
        .enumerate()
        .map(|(i, entry)| {
            task(entry)
                .map_err(|why| format!("`tasks` entry {} (`{}`): {why}", i + 1, entry.trim()))
        })
        .collect()
}

fn task(entry: &str) -> Result<TaskSpec, String> {
    let fields: Vec<&str> = entry.split(',').map(str::trim).collect();
    let &[x, y, kind_text, value, window] = fields.as_slice() else {
        return Err(format!(
            "{} fields, but a task is `x,y,type,value,window`",
            fields.len()
        ));
    };
    let coordinate = |name: &str, text: &str| {
        number(text)
            .filter(|v| (f64::from(f32::MIN)..=f64::from(f32::MAX)).contains(v))
            .ok_or_else(|| format!("{name} `{text}` is not a number of metres"))
    };
    let position = Vec2::new(coordinate("x", x)? as f32, coordinate("y", y)? as f32);
    let kind = kind(kind_text).ok_or_else(|| format!("the type `{kind_text}` must be 1 or 2"))?;
    let value = number(value)
        .filter(|v| *v >= 0.0 && *v <= f64::from(f32::MAX))
        // `-0` is 0.
        .map(f64::abs)
        .ok_or_else(|| format!("the value `{value}` must be a number >= 0"))?
        as f32;
    let window = number(window)
        .filter(|v| *v > 0.0)
        .ok_or_else(|| format!("the window `{window}` must be a number of seconds > 0"))?;
    Ok(TaskSpec {
        position,
        kind,
        value,
        window,
    })
}

/// Reads `robot_types`: `controller:type` pairs separated by commas or spaces, each controller once.
pub fn parse_robot_types(text: &str) -> Result<Vec<(String, Kind)>, String> {
    let mut types: Vec<(String, Kind)> = Vec::new();
    for pair in text.split([',', ' ', '\t', '\n']).filter(|p| !p.is_empty()) {
        let Some((controller, kind_text)) = pair.split_once(':') else {
            return Err(format!(
                "`robot_types` entry `{pair}` is not `controller:type`"
            ));
        };
        if controller.is_empty() {
            return Err(format!("`robot_types` entry `{pair}` names no controller"));
        }
        let kind = kind(kind_text).ok_or_else(|| {
            format!("`robot_types` entry `{pair}`: the type `{kind_text}` must be 1 or 2")
        })?;
        if types.iter().any(|(c, _)| c == controller) {
            return Err(format!(
                "`robot_types` lists controller `{controller}` twice"
            ));
        }
        types.push((controller.to_owned(), kind));
    }
    if types.is_empty() {
        return Err("`robot_types` lists no `controller:type` pair".into());
    }
    Ok(types)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tasks_are_read_in_order() {
        let tasks = parse_tasks(" 2.0,8.0,1,45,200; 8.0, 2.0, 2, 20, 220.5 ;").unwrap();
        assert_eq!(parse_tasks("1,1,1,-0,1").unwrap()[0].value.to_string(), "0");
        assert_eq!(
            tasks,
            vec![
                TaskSpec {
                    position: Vec2::new(2.0, 8.0),
                    kind: Kind::One,
                    value: 45.0,
                    window: 200.0
                },
                TaskSpec {
                    position: Vec2::new(8.0, 2.0),
                    kind: Kind::Two,
                    value: 20.0,
                    window: 220.5
                },
            ]
        );
    }

    #[test]
    fn a_malformed_task_entry_is_named_with_what_is_wrong() {
        let err = |text: &str| parse_tasks(text).unwrap_err();
        assert_eq!(
            err("1,1,1,5,10; 8,2,3,20,220"),
            "`tasks` entry 2 (`8,2,3,20,220`): the type `3` must be 1 or 2"
        );
        assert_eq!(
            err("1,1,1,5"),
            "`tasks` entry 1 (`1,1,1,5`): 4 fields, but a task is `x,y,type,value,window`"
        );
        assert_eq!(
            err("1,1,1,5,10;1,1,1,5,10;q,1,1,5,10"),
            "`tasks` entry 3 (`q,1,1,5,10`): x `q` is not a number of metres"
        );
        assert_eq!(
            err("1,inf,1,5,10"),
            "`tasks` entry 1 (`1,inf,1,5,10`): y `inf` is not a number of metres"
        );
        assert_eq!(
            err("1,1,1,-5,10"),
            "`tasks` entry 1 (`1,1,1,-5,10`): the value `-5` must be a number >= 0"
        );
        assert_eq!(
            err("1,1,1,5,0"),
            "`tasks` entry 1 (`1,1,1,5,0`): the window `0` must be a number of seconds > 0"
        );
        assert_eq!(
            err("1,1,1,5,10;;1,1,1,5,10"),
            "`tasks` entry 2 (``): 1 fields, but a task is `x,y,type,value,window`"
        );
        assert!(err(" ; ").starts_with("`tasks` lists no task"));
        let many = vec!["1,1,1,1,1"; MAX_TASKS + 1].join(";");
        assert_eq!(err(&many), "`tasks` lists 65536 tasks; at most 65535");
    }

    #[test]
    fn robot_types_pair_controllers_with_types() {
        assert_eq!(
            parse_robot_types("scout:1, hauler:2").unwrap(),
            vec![
                ("scout".to_owned(), Kind::One),
                ("hauler".to_owned(), Kind::Two)
            ]
        );
        let err = |text: &str| parse_robot_types(text).unwrap_err();
        assert_eq!(
            err("scout:1 hauler:3"),
            "`robot_types` entry `hauler:3`: the type `3` must be 1 or 2"
        );
        assert_eq!(
            err("scout"),
            "`robot_types` entry `scout` is not `controller:type`"
        );
        assert_eq!(err(":1"), "`robot_types` entry `:1` names no controller");
        assert_eq!(
            err("scout:1,scout:2"),
            "`robot_types` lists controller `scout` twice"
        );
        assert_eq!(err(" , "), "`robot_types` lists no `controller:type` pair");
    }
}
